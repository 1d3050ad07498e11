// Closed concave meshes with known volumes for the decomposition tests: an
// L-shaped prism and a cylindrical cup, each one watertight surface wound
// counter-clockwise seen from outside.
#ifndef RIGID_BODY_SIM_TEST_IO_CONCAVE_MESHES_H_
#define RIGID_BODY_SIM_TEST_IO_CONCAVE_MESHES_H_

#include <array>
#include <cmath>
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

// The area of a regular polygon of `segments` vertices on a circle.
inline double PolygonArea(double radius, int segments) {
  return 0.5 * segments * radius * radius * std::sin(2.0 * M_PI / segments);
}

}  // namespace rigid_body_sim::io::testing

#endif  // RIGID_BODY_SIM_TEST_IO_CONCAVE_MESHES_H_
