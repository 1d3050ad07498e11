// Closed concave meshes with known volumes for the decomposition tests: an
// L-shaped prism and a cylindrical cup, each one watertight surface wound
// counter-clockwise seen from outside.
#ifndef RIGID_BODY_SIM_TEST_IO_CONCAVE_MESHES_H_
#define RIGID_BODY_SIM_TEST_IO_CONCAVE_MESHES_H_

#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io::testing {

inline void AddQuad(physics::TriangleMesh* mesh, int a, int b, int c, int d) {
  mesh->triangles.emplace_back(a, b, c);
  mesh->triangles.emplace_back(a, c, d);
}

// A box [lower, upper].
inline physics::TriangleMesh BoxMesh(const physics::Vec3& lower, const physics::Vec3& upper) {
  physics::TriangleMesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.emplace_back(i & 1 ? upper.x() : lower.x(), i & 2 ? upper.y() : lower.y(),
                               i & 4 ? upper.z() : lower.z());
  }
  for (const auto& q : {std::array<int, 4>{0, 4, 6, 2},
                        {1, 3, 7, 5},
                        {0, 1, 5, 4},
                        {2, 6, 7, 3},
                        {0, 2, 3, 1},
                        {4, 5, 7, 6}}) {
    AddQuad(&mesh, q[0], q[1], q[2], q[3]);
  }
  return mesh;
}

// The L of profile (x, z): (0,0) (length,0) (length,thickness)
// (thickness,thickness) (thickness,height) (0,height), extruded over
// y in [0, depth]. Volume: depth * (length * thickness + thickness *
// (height - thickness)).
inline physics::TriangleMesh LPrism(double length, double height, double thickness, double depth) {
  const double profile[6][2] = {
      {0, 0},     {length, 0}, {length, thickness}, {thickness, thickness}, {thickness, height},
      {0, height}};
  physics::TriangleMesh mesh;
  for (double y : {0.0, depth}) {
    for (const auto& p : profile) mesh.vertices.emplace_back(p[0], y, p[1]);
  }
  // The profile is star-shaped from its corner (0, 0): fans from vertex 0.
  // Seen from -y (outside the y = 0 cap) the profile runs counter-clockwise.
  for (int i = 1; i < 5; ++i) {
    mesh.triangles.emplace_back(0, i, i + 1);
    mesh.triangles.emplace_back(6, 6 + i + 1, 6 + i);
  }
  for (int i = 0; i < 6; ++i) AddQuad(&mesh, i, 6 + i, 6 + (i + 1) % 6, (i + 1) % 6);
  return mesh;
}

// A cup around the z axis: outer radius `outer`, inner radius `inner`,
// from z = 0 to `height`, a cavity down to z = `floor`; circles of
// `segments` vertices. Volume: segment-polygon areas times heights.
inline physics::TriangleMesh Cup(double outer, double inner, double height, double floor,
                                 int segments) {
  physics::TriangleMesh mesh;
  const auto ring = [&](double radius, double z) {
    const int first = static_cast<int>(mesh.vertices.size());
    for (int i = 0; i < segments; ++i) {
      const double angle = 2.0 * M_PI * i / segments;
      mesh.vertices.emplace_back(radius * std::cos(angle), radius * std::sin(angle), z);
    }
    return first;
  };
  const int outer_bottom = ring(outer, 0.0);
  const int outer_top = ring(outer, height);
  const int inner_top = ring(inner, height);
  const int inner_bottom = ring(inner, floor);
  const int bottom_centre = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0.0, 0.0, 0.0);
  const int floor_centre = bottom_centre + 1;
  mesh.vertices.emplace_back(0.0, 0.0, floor);
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    AddQuad(&mesh, outer_bottom + i, outer_bottom + j, outer_top + j, outer_top + i);  // outside
    AddQuad(&mesh, outer_top + i, outer_top + j, inner_top + j, inner_top + i);        // rim
    AddQuad(&mesh, inner_top + i, inner_top + j, inner_bottom + j, inner_bottom + i);  // cavity
    mesh.triangles.emplace_back(floor_centre, inner_bottom + i, inner_bottom + j);     // floor
    mesh.triangles.emplace_back(bottom_centre, outer_bottom + j, outer_bottom + i);    // base
  }
  return mesh;
}

// A closed surface of revolution about the z axis: the profile is a simple
// polygon of (r, z) points, r >= 0, whose points on the axis (r = 0) become
// single vertices; circles of `segments` vertices. Wound outward whichever
// way the profile runs (the signed volume decides).
inline physics::TriangleMesh Revolve(const std::vector<std::array<double, 2>>& profile,
                                     int segments) {
  physics::TriangleMesh mesh;
  std::vector<int> first(profile.size());
  for (std::size_t p = 0; p < profile.size(); ++p) {
    first[p] = static_cast<int>(mesh.vertices.size());
    const int copies = profile[p][0] == 0.0 ? 1 : segments;
    for (int i = 0; i < copies; ++i) {
      const double angle = 2.0 * M_PI * i / segments;
      mesh.vertices.emplace_back(profile[p][0] * std::cos(angle), profile[p][0] * std::sin(angle),
                                 profile[p][1]);
    }
  }
  const auto at = [&](std::size_t p, int i) {
    return profile[p][0] == 0.0 ? first[p] : first[p] + i % segments;
  };
  for (std::size_t p = 0; p < profile.size(); ++p) {
    const std::size_t q = (p + 1) % profile.size();
    for (int i = 0; i < segments; ++i) {
      const int a = at(p, i), b = at(p, i + 1), c = at(q, i + 1), d = at(q, i);
      if (a != b) mesh.triangles.emplace_back(a, b, c);
      if (c != d) mesh.triangles.emplace_back(a, c, d);
    }
  }
  double signed_volume = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    signed_volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  }
  if (signed_volume < 0.0) {
    for (Eigen::Vector3i& t : mesh.triangles) std::swap(t[1], t[2]);
  }
  return mesh;
}

// A hemispherical bowl, open at the top: outer radius `outer`, walls
// `wall` thick, its lowest point at z = 0 and its rim at z = outer;
// `rings` profile points per arc.
inline physics::TriangleMesh Bowl(double outer, double wall, int rings, int segments) {
  std::vector<std::array<double, 2>> profile;
  for (int k = 0; k <= rings; ++k) {  // outside, from the bottom up to the rim
    const double angle = -0.5 * M_PI * (1.0 - static_cast<double>(k) / rings);
    profile.push_back({outer * std::cos(angle), outer + outer * std::sin(angle)});
  }
  const double inner = outer - wall;
  for (int k = rings; k >= 0; --k) {  // inside, from the rim down
    const double angle = -0.5 * M_PI * (1.0 - static_cast<double>(k) / rings);
    profile.push_back({inner * std::cos(angle), outer + inner * std::sin(angle)});
  }
  profile.front()[0] = 0.0;
  profile.back()[0] = 0.0;
  return Revolve(profile, segments);
}

// The area of a regular polygon of `segments` vertices on a circle.
inline double PolygonArea(double radius, int segments) {
  return 0.5 * segments * radius * radius * std::sin(2.0 * M_PI / segments);
}

}  // namespace rigid_body_sim::io::testing

#endif  // RIGID_BODY_SIM_TEST_IO_CONCAVE_MESHES_H_
