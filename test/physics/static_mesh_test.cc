// Static triangle meshes: the tree query against brute force, refusals, and
// bodies resting, sliding, rolling and flying against meshes, checked
// against closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mesh_fixtures_static.h"
#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/world.h"
#include "scene.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::AddGround;
using testing::AddSphere;
using testing::BoxSpec;
using testing::MakeMaterial;
using testing::SphereSpec;
using testing::Translation;

std::shared_ptr<const CollisionMesh> Build(const TriangleMesh& mesh) {
  Result<std::shared_ptr<const CollisionMesh>> built = CollisionMesh::Make(mesh);
  EXPECT_TRUE(built.ok()) << built.message();
  return built.value();
}

BodyId AddStaticMesh(World* world, const TriangleMesh& mesh, const Material& material,
                     const Pose& world_from_mesh = Pose::Identity()) {
  BodyDef def;
  def.is_static = true;
  def.world_from_body = world_from_mesh;
  ShapeDef shape;
  shape.geometry = StaticMesh{Build(mesh)};
  shape.material = material;
  def.shapes.push_back(shape);
  Result<BodyId> id = world->CreateBody(def);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.value();
}

TEST(CollisionMeshTest, TreeQueryMatchesBruteForce) {
  const TriangleMesh terrain = testing::MakeGrid(
      -5.0, -5.0, 0.1, 100, 100, [](double x, double y) { return testing::Hills(x, y, 0.3, 0.7); });
  const auto mesh = Build(terrain);
  EXPECT_EQ(mesh->triangles().size(), 20000u);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> position(-6.0, 6.0);
  std::uniform_real_distribution<double> size(0.0, 1.5);
  std::vector<int> fast;
  std::vector<int> slow;
  std::size_t found = 0;
  for (int query = 0; query < 2000; ++query) {
    const Vec3 lower(position(random), position(random), 0.4 * position(random) / 6.0);
    const Vec3 upper = lower + Vec3(size(random), size(random), 0.3 * size(random));
    fast.clear();
    slow.clear();
    mesh->QueryBox(lower, upper, &fast);
    mesh->BruteForceQueryBox(lower, upper, &slow);
    std::sort(fast.begin(), fast.end());
    ASSERT_EQ(fast, slow) << "query " << query;
    found += fast.size();
  }
  EXPECT_GT(found, 10000u);  // the queries do hit triangles
}

TEST(CollisionMeshTest, FindsEdgeFolds) {
  TriangleMesh box;
  testing::AppendBox(Vec3::Zero(), Vec3::Ones(), &box);
  const auto mesh = Build(box);
  int convex = 0;
  int flat = 0;
  for (const CollisionMesh::Triangle& triangle : mesh->triangles()) {
    for (const CollisionMesh::EdgeFold fold : triangle.edge_folds) {
      convex += fold == CollisionMesh::EdgeFold::kConvex;
      flat += fold == CollisionMesh::EdgeFold::kFlat;
    }
  }
  EXPECT_EQ(convex, 24);  // 12 cube edges, seen from both sides
  EXPECT_EQ(flat, 12);    // the 6 face diagonals
  const TriangleMesh bin = testing::MakeBin(Vec3(0.4, 0.3, 0.2), 0.005);
  EXPECT_EQ(Build(bin)->triangles().size(), 60u);
}

TEST(CollisionMeshTest, RefusesBadMeshes) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3::Zero(), Vec3::UnitX(), Vec3(0.0, std::nan(""), 0.0)};
  mesh.triangles = {Eigen::Vector3i(0, 1, 2)};
  Result<std::shared_ptr<const CollisionMesh>> built = CollisionMesh::Make(mesh);
  ASSERT_FALSE(built.ok());
  EXPECT_NE(built.message().find("vertex 2"), std::string::npos) << built.message();
  mesh.vertices[2] = Vec3::UnitY();
  mesh.triangles = {Eigen::Vector3i(0, 1, 3)};
  built = CollisionMesh::Make(mesh);
  ASSERT_FALSE(built.ok());
  EXPECT_NE(built.message().find("index 3 outside [0, 2]"), std::string::npos) << built.message();
  mesh.triangles = {Eigen::Vector3i(0, 1, 1)};
  built = CollisionMesh::Make(mesh);
  ASSERT_FALSE(built.ok());
  EXPECT_NE(built.message().find("no triangle of non-zero area"), std::string::npos);
}

TEST(CollisionMeshTest, RefusedOnMovingBodies) {
  World world;
  TriangleMesh box;
  testing::AppendBox(Vec3::Zero(), Vec3::Ones(), &box);
  BodyDef def;
  def.mass_properties = BoxMassProperties(1.0, Vec3::Ones());
  ShapeDef shape;
  shape.geometry = StaticMesh{Build(box)};
  def.shapes.push_back(shape);
  Result<BodyId> id = world.CreateBody(def);
  ASSERT_FALSE(id.ok());
  EXPECT_NE(id.message().find("needs a static body"), std::string::npos) << id.message();
  shape.geometry = StaticMesh{Build(box), 2};
  def.shapes = {shape};
  def.is_static = true;
  id = world.CreateBody(def);
  ASSERT_FALSE(id.ok());
  EXPECT_NE(id.message().find("must be 0, got 2"), std::string::npos) << id.message();
}

// A 10 cm box dropped into a 40 x 30 x 20 cm bin with 5 mm walls rests on
// the bin's floor: its centre at floor + 5 cm.
TEST(StaticMeshWorldTest, BoxRestsOnBinFloor) {
  World world;
  const double wall = 0.005;
  const BodyId bin =
      AddStaticMesh(&world, testing::MakeBin(Vec3(0.4, 0.3, 0.2), wall), MakeMaterial(0.5, 0.0));
  BoxSpec spec;
  spec.size = Vec3::Constant(0.1);
  spec.world_from_body = Translation(0.03, -0.02, 0.35);
  spec.world_from_body.rotation = Quat(Eigen::AngleAxisd(0.3, Vec3(1.0, 2.0, 0.5).normalized()));
  spec.material = MakeMaterial(0.5, 0.0);
  const BodyId box = AddBox(&world, spec);
  for (int step = 0; step < 3 * 240; ++step) world.Step();
  const Body& body = world.GetBody(box);
  EXPECT_NEAR(body.position.z(), wall + 0.05, 1e-3);
  EXPECT_LT(body.linear_velocity.norm(), 1e-3);
  // Resting on a face: its up axis is vertical.
  const Vec3 up = body.WorldFromBody().rotation * Vec3::UnitZ();
  EXPECT_GT(std::abs(up.z()) + std::abs(up.x()) + std::abs(up.y()), 0.999);
  bool reported = false;
  for (const ContactReport& report : world.contacts()) {
    if (report.body_b == bin) {
      EXPECT_EQ(report.shape_b, 0);  // the mesh, not a slot copy
      reported = true;
    }
  }
  EXPECT_TRUE(reported || !body.awake);
}

// A box sliding across a floor of 5 cm cells (two triangles each) keeps a
// straight, level path: it decelerates at mu g and never bumps on the
// triangles' internal edges.
TEST(StaticMeshWorldTest, BoxSlidesSmoothlyOverTessellatedFloor) {
  WorldSettings settings;
  World world(settings);
  AddStaticMesh(&world,
                testing::MakeGrid(-1.0, -0.5, 0.05, 80, 20, [](double, double) { return 0.0; }),
                MakeMaterial(0.2, 0.0));
  BoxSpec spec;
  spec.size = Vec3::Constant(0.1);
  spec.world_from_body = Translation(-0.8, 0.013, 0.05);
  spec.linear_velocity = Vec3(1.5, 0.0, 0.0);
  spec.material = MakeMaterial(0.2, 0.0);
  const BodyId box = AddBox(&world, spec);
  double lateral = 0.0;
  double vertical_speed = 0.0;
  for (int step = 0; step < 240; ++step) {
    world.Step();
    const Body& body = world.GetBody(box);
    lateral = std::max(lateral, std::abs(body.position.y() - 0.013));
    if (step > 2) vertical_speed = std::max(vertical_speed, std::abs(body.linear_velocity.z()));
  }
  const Body& body = world.GetBody(box);
  EXPECT_LT(lateral, 1e-4);
  EXPECT_LT(vertical_speed, 1e-3);
  // mu = 0.2: it stops after v^2 / (2 mu g) = 0.5734 m.
  const double distance = 1.5 * 1.5 / (2.0 * 0.2 * 9.81);
  EXPECT_NEAR(body.position.x(), -0.8 + distance, 5e-3);
  EXPECT_NEAR(body.position.z(), 0.05, 1e-3);
}

// A 5 cm ball rolled at 1 m/s passes under a table top (30 cm high) between
// its legs and comes out the other side at the rolling speed 5/7 of 1 m/s.
TEST(StaticMeshWorldTest, BallRollsUnderTable) {
  World world;
  AddGround(&world, MakeMaterial(0.5, 0.0));
  AddStaticMesh(&world, testing::MakeTable(Vec3(1.0, 0.8, 0.3), 0.03, 0.05),
                MakeMaterial(0.5, 0.0));
  SphereSpec spec;
  spec.radius = 0.025;
  spec.mass = 0.05;
  spec.world_from_body = Translation(-1.2, 0.0, 0.025);
  spec.linear_velocity = Vec3(1.0, 0.0, 0.0);
  spec.material = MakeMaterial(0.5, 0.0);
  const BodyId ball = AddSphere(&world, spec);
  for (int step = 0; step < 4 * 240; ++step) world.Step();
  const Body& body = world.GetBody(ball);
  EXPECT_GT(body.position.x(), 0.8);
  EXPECT_NEAR(body.position.y(), 0.0, 1e-6);
  EXPECT_NEAR(body.position.z(), 0.025, 1e-4);
  EXPECT_NEAR(body.linear_velocity.x(), 5.0 / 7.0, 1e-2);
}

// A ball too large for the gap stops against the table top's edge instead.
TEST(StaticMeshWorldTest, LargeBallStopsAtTableTop) {
  World world;
  AddGround(&world, MakeMaterial(0.5, 0.0));
  AddStaticMesh(&world, testing::MakeTable(Vec3(1.0, 0.8, 0.3), 0.03, 0.05),
                MakeMaterial(0.5, 0.0));
  SphereSpec spec;
  spec.radius = 0.2;
  spec.world_from_body = Translation(-1.2, 0.0, 0.2);
  spec.linear_velocity = Vec3(1.0, 0.0, 0.0);
  const BodyId ball = AddSphere(&world, spec);
  for (int step = 0; step < 4 * 240; ++step) world.Step();
  const Body& body = world.GetBody(ball);
  // The table top's lower edge is at (-0.5, 0.27): the ball touches it at
  // x = -0.5 - sqrt(0.2^2 - 0.07^2).
  EXPECT_LT(body.position.x(), -0.5 - std::sqrt(0.04 - 0.07 * 0.07) + 1e-3);
}

// A sphere fired at 200 m/s (0.83 m a step) stops at a wall instead of
// passing through: a wall of two triangles with no thickness, hit on its
// front, and a closed 2 mm slab, hit from either side. It bounces back at
// e = 0.5.
TEST(StaticMeshWorldTest, FastSphereDoesNotPassThinWall) {
  TriangleMesh sheet;
  sheet.vertices = {Vec3(1.0, -1.0, -1.0), Vec3(1.0, 1.0, -1.0), Vec3(1.0, 1.0, 1.0),
                    Vec3(1.0, -1.0, 1.0)};
  sheet.triangles = {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(0, 2, 3)};  // facing +x
  TriangleMesh slab;
  testing::AppendBox(Vec3(0.999, -1.0, -1.0), Vec3(1.001, 1.0, 1.0), &slab);
  struct Case {
    const TriangleMesh* wall;
    double side;  // +1: coming from -x, -1: from +x
  };
  for (const Case& shot : {Case{&sheet, -1.0}, Case{&slab, 1.0}, Case{&slab, -1.0}}) {
    WorldSettings settings;
    settings.gravity = Vec3::Zero();
    World world(settings);
    AddStaticMesh(&world, *shot.wall, MakeMaterial(0.0, 0.5));
    SphereSpec spec;
    spec.radius = 0.05;
    spec.world_from_body = Translation(1.0 - shot.side * 3.0, 0.0, 0.0);
    spec.linear_velocity = Vec3(shot.side * 200.0, 0.0, 0.0);
    spec.material = MakeMaterial(0.0, 0.5);
    const BodyId ball = AddSphere(&world, spec);
    for (int step = 0; step < 60; ++step) world.Step();
    const Body& body = world.GetBody(ball);
    const double half = shot.wall == &slab ? 0.001 : 0.0;
    EXPECT_LT(shot.side * (body.position.x() - 1.0), -0.05 - half + 1e-3) << "side " << shot.side;
    EXPECT_NEAR(body.linear_velocity.x(), -shot.side * 100.0, 1.0) << "side " << shot.side;
  }
}

// A cylinder lying on a tessellated floor rests at height r, standing at h.
TEST(StaticMeshWorldTest, CylinderRestsOnMesh) {
  for (const bool standing : {false, true}) {
    World world;
    AddStaticMesh(&world,
                  testing::MakeGrid(-1.0, -1.0, 0.1, 20, 20, [](double, double) { return 0.0; }),
                  MakeMaterial(0.5, 0.0));
    BodyDef def;
    def.world_from_body = Translation(0.03, 0.02, 0.2);
    if (!standing) def.world_from_body.rotation = Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()));
    def.mass_properties = CylinderMassProperties(1000.0, 0.05, 0.3);
    ShapeDef shape;
    shape.geometry = Cylinder{0.05, 0.15};
    def.shapes.push_back(shape);
    const BodyId cylinder = world.CreateBody(def).value();
    for (int step = 0; step < 2 * 240; ++step) world.Step();
    const Body& body = world.GetBody(cylinder);
    EXPECT_NEAR(body.position.z(), standing ? 0.15 : 0.05, 1e-3) << "standing " << standing;
    EXPECT_LT(body.linear_velocity.norm(), 1e-2);
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics
