// Closed triangle meshes with known analytic mass properties, shared by the
// geometry tests.
#ifndef RIGID_BODY_SIM_TEST_PHYSICS_MESH_FIXTURES_H_
#define RIGID_BODY_SIM_TEST_PHYSICS_MESH_FIXTURES_H_

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "rigid_body_sim/physics/mass_properties.h"

namespace rigid_body_sim::physics::testing {

// Makes every triangle counter-clockwise seen from outside, for a convex
// mesh containing the origin: there the outward normal n of a face
// satisfies n . p > 0 for any point p of the face.
inline void OrientOutward(TriangleMesh& mesh) {
  for (Eigen::Vector3i& triangle : mesh.triangles) {
    const Vec3& a = mesh.vertices[triangle[0]];
    const Vec3& b = mesh.vertices[triangle[1]];
    const Vec3& c = mesh.vertices[triangle[2]];
    if ((b - a).cross(c - a).dot(a + b + c) < 0.0) std::swap(triangle[1], triangle[2]);
  }
}

// Centred box of full edge lengths `size`, two triangles per face.
inline TriangleMesh BoxMesh(const Vec3& size) {
  TriangleMesh mesh;
  for (int i = 0; i < 8; ++i) {
    Vec3 corner;
    for (int k = 0; k < 3; ++k) corner[k] = ((i >> k) & 1 ? 0.5 : -0.5) * size[k];
    mesh.vertices.push_back(corner);
  }
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3;
    const int c = (a + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      const int p0 = side << a;
      const int p1 = p0 | (1 << b);
      const int p2 = p0 | (1 << b) | (1 << c);
      const int p3 = p0 | (1 << c);
      mesh.triangles.emplace_back(p0, p1, p2);
      mesh.triangles.emplace_back(p0, p2, p3);
    }
  }
  OrientOutward(mesh);
  return mesh;
}

// Icosahedron (vertices the cyclic permutations of (0, +-1, +-phi), faces
// the triples at mutual distance 2) subdivided `levels` times by edge
// midpoints projected onto the sphere: 20 * 4^levels triangles.
inline TriangleMesh Icosphere(double radius, int levels) {
  const double phi = 0.5 * (1.0 + std::sqrt(5.0));
  std::vector<Vec3> unit;
  for (int s1 : {-1, 1}) {
    for (int s2 : {-1, 1}) {
      const Vec3 p(0.0, s1 * 1.0, s2 * phi);
      unit.emplace_back(p.x(), p.y(), p.z());
      unit.emplace_back(p.z(), p.x(), p.y());
      unit.emplace_back(p.y(), p.z(), p.x());
    }
  }
  TriangleMesh mesh;
  const int n = static_cast<int>(unit.size());
  auto is_edge = [&](int i, int j) { return std::abs((unit[i] - unit[j]).norm() - 2.0) < 1e-9; };
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      for (int k = j + 1; k < n; ++k) {
        if (is_edge(i, j) && is_edge(j, k) && is_edge(i, k)) mesh.triangles.emplace_back(i, j, k);
      }
    }
  }
  for (const Vec3& p : unit) mesh.vertices.push_back(radius * p.normalized());
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto midpoint_of = [&](int i, int j) {
      const std::pair<int, int> key(std::min(i, j), std::max(i, j));
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      const int index = static_cast<int>(mesh.vertices.size());
      mesh.vertices.push_back(radius * (mesh.vertices[i] + mesh.vertices[j]).normalized());
      midpoint.emplace(key, index);
      return index;
    };
    std::vector<Eigen::Vector3i> finer;
    for (const Eigen::Vector3i& t : mesh.triangles) {
      const int ab = midpoint_of(t[0], t[1]);
      const int bc = midpoint_of(t[1], t[2]);
      const int ca = midpoint_of(t[2], t[0]);
      finer.emplace_back(t[0], ab, ca);
      finer.emplace_back(ab, t[1], bc);
      finer.emplace_back(ca, bc, t[2]);
      finer.emplace_back(ab, bc, ca);
    }
    mesh.triangles = std::move(finer);
  }
  OrientOutward(mesh);
  return mesh;
}

// Regular `segments`-gon prism inscribed in a cylinder (axis z, centred),
// caps fanned from their centres.
inline TriangleMesh CylinderMesh(double radius, double length, int segments) {
  TriangleMesh mesh;
  for (int i = 0; i < segments; ++i) {
    const double angle = 2.0 * kPi * i / segments;
    mesh.vertices.emplace_back(radius * std::cos(angle), radius * std::sin(angle), -0.5 * length);
    mesh.vertices.emplace_back(radius * std::cos(angle), radius * std::sin(angle), 0.5 * length);
  }
  const int bottom_centre = 2 * segments;
  const int top_centre = 2 * segments + 1;
  mesh.vertices.emplace_back(0.0, 0.0, -0.5 * length);
  mesh.vertices.emplace_back(0.0, 0.0, 0.5 * length);
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    mesh.triangles.emplace_back(2 * i, 2 * j, 2 * j + 1);
    mesh.triangles.emplace_back(2 * i, 2 * j + 1, 2 * i + 1);
    mesh.triangles.emplace_back(top_centre, 2 * i + 1, 2 * j + 1);
    mesh.triangles.emplace_back(bottom_centre, 2 * j, 2 * i);
  }
  OrientOutward(mesh);
  return mesh;
}

// Exact mass properties of that prism: cross-section area
// A = n/2 r^2 sin(2 pi/n); summing the triangles (0, p_i, p_i+1) gives the
// polar moment J = M r^2 (2 + cos(2 pi/n)) / 6 and I_xx = I_yy = J/2 + M l^2/12.
inline MassProperties PrismMassProperties(double density, double radius, double length,
                                          int segments) {
  const double angle = 2.0 * kPi / segments;
  MassProperties result;
  result.mass = density * 0.5 * segments * radius * radius * std::sin(angle) * length;
  const double polar = result.mass * radius * radius * (2.0 + std::cos(angle)) / 6.0;
  const double transverse = 0.5 * polar + result.mass * length * length / 12.0;
  result.inertia_about_com = Vec3(transverse, transverse, polar).asDiagonal();
  return result;
}

inline ::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\"" << text << "\" does not contain \"" << part << "\"";
}

// Largest entry of |a - b| relative to the largest entry of |b|.
inline double RelativeDifference(const Mat3& a, const Mat3& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

}  // namespace rigid_body_sim::physics::testing

#endif  // RIGID_BODY_SIM_TEST_PHYSICS_MESH_FIXTURES_H_
