// A box coming to rest on curved static meshes: the manifold of a mesh
// group keeps the points that can touch within the step, and a box dropped
// on the benchmark's rolling hills rests as soon as on flat ground.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>

#include "mesh_fixtures_static.h"
#include "physics/collision/mesh_collision.h"
#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/world.h"
#include "scene.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::BoxSpec;
using testing::Build;
using testing::MakeMaterial;
using testing::Translation;

// A unit box lying level across a gentle ridge z = -0.01 |x| (both roof
// faces within the 9 degrees of one group) touches it along the ridge line,
// 0.1 mm deep; the corners at x = +-0.5 hang 5 mm above the roof, within
// the contact distance of 1 cm. When the box can close only 1 mm in the
// step, the corners cannot touch: the four points of the manifold are all
// on the ridge, where the box pivots, and the normal is the ridge's mean
// (vertical), not a far corner's face.
TEST(TerrainRestTest, MeshGroupKeepsPointsWithinReach) {
  const double slope = 0.01;
  const std::shared_ptr<const CollisionMesh> roof = Build(testing::MakeGrid(
      -1.0, -1.0, 1.0, 2, 2, [slope](double x, double) { return -slope * std::abs(x); }));
  const ShapeGeometry box =
      std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3::Ones()));
  ConvexMeshPair pair{&box, Translation(0.05, 0.1, 0.5 - 1e-4), roof.get(), Pose::Identity(), 0.01};
  pair.reach = 1e-3;
  MeshContacts contacts;
  CollideConvexMesh(pair, &contacts);
  const ContactManifold& manifold = contacts.manifolds[0];
  ASSERT_GE(manifold.point_count, 2);
  double highest = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < manifold.point_count; ++i) {
    EXPECT_LE(manifold.points[i].separation, pair.reach);
    EXPECT_NEAR(manifold.points[i].position_world.x(), 0.0, 1e-9);
    highest = std::max(highest, manifold.points[i].separation);
  }
  EXPECT_GT(manifold.normal_world.z(), 1.0 - 1e-12);
  std::printf("ridge: %d points, the highest %+.6f m apart, normal z %.12f\n", manifold.point_count,
              highest, manifold.normal_world.z());
  // With no bound on the step's motion every point is a candidate, as for
  // the callers that do not pass one: the corners are kept then.
  pair.reach = std::numeric_limits<double>::infinity();
  CollideConvexMesh(pair, &contacts);
  highest = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < contacts.manifolds[0].point_count; ++i) {
    highest = std::max(highest, contacts.manifolds[0].points[i].separation);
  }
  EXPECT_NEAR(highest, 0.5 * slope - 1e-4 + 0.05 * slope, 1e-9);
}

// A contact point's feature names its triangle in B's index (the
// triangle's place in the mesh's tree order x 16, plus the feature of the
// triangle's prism), so that the contact cache tells points of different
// triangles apart on meshes of any size. A box rests on the one triangle
// near the origin of 10,001 (5,000 far off on either side, so the tree puts
// it near the middle, past 4,096): its features name that triangle, not its
// place mod 4,096 as a 16-bit index did.
TEST(TerrainRestTest, ContactFeaturesNameTrianglesBeyond4096) {
  constexpr int kSide = 5000;
  TriangleMesh mesh;
  for (int t = -kSide; t <= kSide; ++t) {
    const Vec3 origin = t == 0 ? Vec3(-2.0, -2.0, 0.0) : Vec3(100.0 * t, 0.0, 0.0);
    const int first = static_cast<int>(mesh.vertices.size());
    mesh.vertices.push_back(origin);
    mesh.vertices.push_back(origin + Vec3(6.0, 0.0, 0.0));
    mesh.vertices.push_back(origin + Vec3(0.0, 6.0, 0.0));
    mesh.triangles.emplace_back(first, first + 1, first + 2);
  }
  const std::shared_ptr<const CollisionMesh> ground = Build(mesh);
  std::uint32_t under = 0;
  while (ground->vertices()[ground->triangles()[under].vertices[0]].norm() > 10.0) ++under;
  ASSERT_GE(under, 4096u);
  const ShapeGeometry box =
      std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3::Ones()));
  ConvexMeshPair pair{&box, Translation(0.0, 0.0, 0.5 - 1e-4), ground.get(), Pose::Identity(),
                      0.01};
  MeshContacts contacts;
  CollideConvexMesh(pair, &contacts);
  const ContactManifold& manifold = contacts.manifolds[0];
  ASSERT_EQ(manifold.point_count, 4);
  for (int i = 0; i < manifold.point_count; ++i) {
    EXPECT_EQ(manifold.points[i].feature.index_b / 16u, under) << i;
  }
}

// The benchmark's hills (terrain_100): z = 0.5 sin(x / 3) cos(y / 3) m, as a
// grid of 40/224 m cells, here a 4.1 m square patch of it.
constexpr double kCell = 40.0 / 224.0;  // m
constexpr int kCells = 23;

double HillHeight(double amplitude, double x, double y) {
  return testing::Hills(x, y, amplitude, 3.0);
}

// The height of the grid's triangles (MakeGrid's split of each cell) at
// (x, y), m.
double GridHeight(double amplitude, double x0, double y0, double x, double y) {
  const int i = static_cast<int>(std::floor((x - x0) / kCell));
  const int j = static_cast<int>(std::floor((y - y0) / kCell));
  const double fx = (x - x0) / kCell - i;
  const double fy = (y - y0) / kCell - j;
  const auto h = [&](int a, int b) {
    return HillHeight(amplitude, x0 + a * kCell, y0 + b * kCell);
  };
  if (fx >= fy)
    return h(i, j) + fx * (h(i + 1, j) - h(i, j)) + fy * (h(i + 1, j + 1) - h(i + 1, j));
  return h(i, j) + fy * (h(i, j + 1) - h(i, j)) + fx * (h(i + 1, j + 1) - h(i, j + 1));
}

struct DropResult {
  double asleep_after = -1.0;   // s, -1 if still awake after 10 s
  double lowest_corner = 0.0;   // m, the box's lowest corner above the mesh at the end
  double deepest_vertex = 0.0;  // m, the mesh vertex deepest inside the box at the end
};

// Drops a unit box of the benchmark (1 kg, mu = 0.5) from 1.5 m above the
// hills at (x, y), turned by `yaw` about z, onto a patch of the hills of
// `amplitude` (0: flat) centred there, and steps until it sleeps.
DropResult DropOnHills(double amplitude, double x, double y, double yaw) {
  const double x0 = -20.0 + std::floor((x - 2.0 + 20.0) / kCell) * kCell;
  const double y0 = -20.0 + std::floor((y - 2.0 + 20.0) / kCell) * kCell;
  const TriangleMesh patch =
      testing::MakeGrid(x0, y0, kCell, kCells, kCells,
                        [amplitude](double u, double v) { return HillHeight(amplitude, u, v); });
  World world;
  BodyDef ground;
  ground.is_static = true;
  ShapeDef mesh;
  mesh.geometry = StaticMesh{Build(patch)};
  mesh.material = MakeMaterial(0.5, 0.0);
  ground.shapes.push_back(mesh);
  EXPECT_TRUE(world.CreateBody(ground).ok());
  BoxSpec spec;
  spec.size = Vec3::Ones();
  spec.world_from_body = Translation(x, y, HillHeight(amplitude, x, y) + 1.5);
  spec.world_from_body.rotation = Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
  spec.material = MakeMaterial(0.5, 0.0);
  const BodyId box = AddBox(&world, spec);
  DropResult result;
  for (int step = 0; step < 10 * 240 && result.asleep_after < 0.0; ++step) {
    world.Step();
    if (!world.GetBody(box).awake) result.asleep_after = (step + 1) / 240.0;
  }
  const Pose world_from_box = world.GetBody(box).WorldFromBody();
  result.lowest_corner = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner =
        world_from_box * Vec3(k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 : -0.5, k & 4 ? 0.5 : -0.5);
    result.lowest_corner = std::min(
        result.lowest_corner, corner.z() - GridHeight(amplitude, x0, y0, corner.x(), corner.y()));
  }
  for (const Vec3& vertex : patch.vertices) {
    const Vec3 in_box = world_from_box.Inverse() * vertex;
    const double depth = 0.5 - in_box.cwiseAbs().maxCoeff();
    result.deepest_vertex = std::max(result.deepest_vertex, depth);
  }
  return result;
}

// terrain_100's box 62 lands on a slope and settles with its far edge over
// a ridge of the hills: the support moves along that edge from one
// triangle edge to the next. It used to rock for nearly 10 s (the manifold
// kept far corners and dropped the next pivot, a fraction of a millimetre
// away). Dropped the same way on a flat floor it sleeps after the fall
// (0.45 s) and the 0.5 s of sleep.time_to_sleep; on the hills it must
// sleep within twice that, and rest above the triangles: no corner below
// them, and no vertex of them inside the box, by more than the
// penetration slop (0.1 mm) and its slant over a 10 degree slope.
TEST(TerrainRestTest, BoxDroppedOnHillsRestsAsSoonAsOnFlatGround) {
  const double x = -7.5;
  const double y = 4.5;
  const double yaw = 0.3 * 62;
  const DropResult flat = DropOnHills(0.0, x, y, yaw);
  const DropResult hills = DropOnHills(0.5, x, y, yaw);
  std::printf(
      "asleep after %.3f s on the hills, %.3f s on flat ground; lowest corner %+.6f m, "
      "deepest mesh vertex in the box %.6f m\n",
      hills.asleep_after, flat.asleep_after, hills.lowest_corner, hills.deepest_vertex);
  ASSERT_GT(flat.asleep_after, 0.0);
  ASSERT_GT(hills.asleep_after, 0.0);
  EXPECT_LE(hills.asleep_after, 2.0 * flat.asleep_after);
  const double slop = WorldSettings().solver.penetration_slop / std::cos(10.0 * M_PI / 180.0);
  EXPECT_GE(hills.lowest_corner, -slop);
  EXPECT_LE(hills.deepest_vertex, slop);
}

}  // namespace
}  // namespace rigid_body_sim::physics
