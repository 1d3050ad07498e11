// Triangle meshes for the static-mesh tests: boxes as
// triangles, tessellated floors, a bin, a table and a terrain.
#ifndef RIGID_BODY_SIM_TEST_PHYSICS_MESH_FIXTURES_STATIC_H_
#define RIGID_BODY_SIM_TEST_PHYSICS_MESH_FIXTURES_STATIC_H_

#include <cmath>
#include <functional>
#include <memory>
#include <utility>

#include <gtest/gtest.h>

#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/mass_properties.h"

namespace rigid_body_sim::physics::testing {

// The collision mesh of `mesh`, which a test expects to be valid.
inline std::shared_ptr<const CollisionMesh> Build(const TriangleMesh& mesh) {
  Result<std::shared_ptr<const CollisionMesh>> built = CollisionMesh::Make(mesh);
  EXPECT_TRUE(built.ok()) << built.message();
  return built.value();
}

// Appends the closed box [lower, upper] as 12 outward triangles.
inline void AppendBox(const Vec3& lower, const Vec3& upper, TriangleMesh* mesh) {
  const int base = static_cast<int>(mesh->vertices.size());
  for (int i = 0; i < 8; ++i) {
    mesh->vertices.emplace_back((i & 1) ? upper.x() : lower.x(), (i & 2) ? upper.y() : lower.y(),
                                (i & 4) ? upper.z() : lower.z());
  }
  // Quads counter-clockwise from outside: -x, +x, -y, +y, -z, +z.
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& quad : quads) {
    mesh->triangles.emplace_back(base + quad[0], base + quad[1], base + quad[2]);
    mesh->triangles.emplace_back(base + quad[0], base + quad[2], base + quad[3]);
  }
}

// The surface z = height(x, y) over [x0, x0 + nx cell] x [y0, y0 + ny cell],
// two triangles per cell, facing up.
inline TriangleMesh MakeGrid(double x0, double y0, double cell, int nx, int ny,
                             const std::function<double(double, double)>& height) {
  TriangleMesh mesh;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const double x = x0 + i * cell;
      const double y = y0 + j * cell;
      mesh.vertices.emplace_back(x, y, height(x, y));
    }
  }
  const auto at = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      mesh.triangles.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      mesh.triangles.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
  return mesh;
}

// Reverses the winding of the triangles t for which reverse(t) holds, as
// mesh files with faces exported the wrong way have them.
inline void ReverseTriangles(const std::function<bool(int)>& reverse, TriangleMesh* mesh) {
  for (int t = 0; t < static_cast<int>(mesh->triangles.size()); ++t) {
    if (reverse(t)) std::swap(mesh->triangles[t][1], mesh->triangles[t][2]);
  }
}

// An open bin centred on the z axis: outer size `outer` (x, y, z), walls and
// floor `wall` thick, the floor's underside at z = 0.
inline TriangleMesh MakeBin(const Vec3& outer, double wall) {
  TriangleMesh mesh;
  const double hx = 0.5 * outer.x();
  const double hy = 0.5 * outer.y();
  AppendBox(Vec3(-hx, -hy, 0.0), Vec3(hx, hy, wall), &mesh);
  AppendBox(Vec3(-hx, -hy, wall), Vec3(-hx + wall, hy, outer.z()), &mesh);
  AppendBox(Vec3(hx - wall, -hy, wall), Vec3(hx, hy, outer.z()), &mesh);
  AppendBox(Vec3(-hx + wall, -hy, wall), Vec3(hx - wall, -hy + wall, outer.z()), &mesh);
  AppendBox(Vec3(-hx + wall, hy - wall, wall), Vec3(hx - wall, hy, outer.z()), &mesh);
  return mesh;
}

// A table centred on the z axis: a top of `top` (x, y) size from
// z = height - thickness to height, on four square legs of side `leg` at its
// corners.
inline TriangleMesh MakeTable(const Vec3& top, double thickness, double leg) {
  TriangleMesh mesh;
  const double hx = 0.5 * top.x();
  const double hy = 0.5 * top.y();
  const double under = top.z() - thickness;
  AppendBox(Vec3(-hx, -hy, under), Vec3(hx, hy, top.z()), &mesh);
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      const Vec3 corner(sx * (hx - 0.5 * leg), sy * (hy - 0.5 * leg), 0.0);
      AppendBox(corner - Vec3(0.5 * leg, 0.5 * leg, 0.0),
                corner + Vec3(0.5 * leg, 0.5 * leg, under), &mesh);
    }
  }
  return mesh;
}

// Rolling hills: z = amplitude sin(x / wavelength) cos(y / wavelength).
inline double Hills(double x, double y, double amplitude, double wavelength) {
  return amplitude * std::sin(x / wavelength) * std::cos(y / wavelength);
}

}  // namespace rigid_body_sim::physics::testing

#endif  // RIGID_BODY_SIM_TEST_PHYSICS_MESH_FIXTURES_STATIC_H_
