// Static triangle meshes: the tree query against brute force, refusals, and
// bodies resting, sliding, rolling and flying against meshes, checked
// against closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "mesh_fixtures_static.h"
#include "physics/collision/mesh_collision.h"
#include "physics/geometry/mesh_orientation.h"
#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/world.h"
#include "scene.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::AddGround;
using testing::AddSphere;
using testing::BoxSpec;
using testing::Build;
using testing::MakeMaterial;
using testing::SphereSpec;
using testing::Translation;

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

// A floor of 5 cm cells (two triangles each), 2 m x 1 m, at z = 0.
TriangleMesh SlidingFloor() {
  return testing::MakeGrid(-1.0, -0.5, 0.05, 80, 20, [](double, double) { return 0.0; });
}

// A box sliding across a floor of 5 cm cells (two triangles each) keeps a
// straight, level path: it decelerates at mu g and never bumps on the
// triangles' internal edges.
void ExpectSmoothSlide(const TriangleMesh& floor) {
  WorldSettings settings;
  World world(settings);
  AddStaticMesh(&world, floor, MakeMaterial(0.2, 0.0));
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
  std::printf("slide: lateral %.3g m, |v_z| %.3g m/s, stop x %.6f m (closed form %.6f), z %.6f m\n",
              lateral, vertical_speed, body.position.x(), -0.8 + distance, body.position.z());
}

TEST(StaticMeshWorldTest, BoxSlidesSmoothlyOverTessellatedFloor) {
  ExpectSmoothSlide(SlidingFloor());
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
// passing through: a wall of two triangles with no thickness (an open
// sheet, two-sided) and a closed 2 mm slab, each hit from either side. It
// bounces back at e = 0.5.
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
  for (const Case& shot :
       {Case{&sheet, -1.0}, Case{&sheet, 1.0}, Case{&slab, 1.0}, Case{&slab, -1.0}}) {
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
    std::printf("%s from %s: x %.6f m, v_x %.4f m/s\n", shot.wall == &slab ? "slab" : "sheet",
                shot.side > 0.0 ? "-x" : "+x", body.position.x(), body.linear_velocity.x());
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

// The signed volume of a triangle mesh, sum of a . (b x c) / 6: positive
// when a closed mesh's normals point out.
double SignedVolume(const std::vector<Vec3>& vertices,
                    const std::vector<std::array<int, 3>>& triangles) {
  double volume = 0.0;
  for (const std::array<int, 3>& t : triangles) {
    volume += vertices[t[0]].dot(vertices[t[1]].cross(vertices[t[2]])) / 6.0;
  }
  return volume;
}

std::vector<std::array<int, 3>> Corners(const TriangleMesh& mesh) {
  std::vector<std::array<int, 3>> corners;
  for (const Eigen::Vector3i& t : mesh.triangles) corners.push_back({t[0], t[1], t[2]});
  return corners;
}

// A cube (1 x 2 x 3 m) with five of its twelve triangles reversed, and one
// turned wholly inside out: after orientation every edge is run once in
// each direction and the volume is +6 m^3.
TEST(MeshOrientationTest, ClosedMeshBecomesConsistentAndOutward) {
  for (const bool inside_out : {false, true}) {
    TriangleMesh cube;
    testing::AppendBox(Vec3(-0.5, -1.0, 0.5), Vec3(0.5, 1.0, 3.5), &cube);
    testing::ReverseTriangles(
        [inside_out](int t) {
          return inside_out || t == 0 || t == 3 || t == 4 || t == 7 || t == 11;
        },
        &cube);
    std::vector<std::array<int, 3>> corners = Corners(cube);
    const MeshOrientation orientation = OrientComponents(cube.vertices, corners);
    EXPECT_EQ(orientation.components, 1);
    std::map<std::pair<int, int>, int> runs;  // directed edge -> triangles running it
    for (std::size_t t = 0; t < corners.size(); ++t) {
      EXPECT_EQ(orientation.open[t], 0);
      if (orientation.flip[t] != 0) std::swap(corners[t][1], corners[t][2]);
      for (int k = 0; k < 3; ++k) ++runs[{corners[t][k], corners[t][(k + 1) % 3]}];
    }
    EXPECT_EQ(runs.size(), 36u);  // 18 edges, each both ways
    for (const auto& [edge, count] : runs) {
      EXPECT_EQ(count, 1) << edge.first << " -> " << edge.second;
      EXPECT_EQ(runs.count({edge.second, edge.first}), 1u) << edge.first << " -> " << edge.second;
    }
    EXPECT_NEAR(SignedVolume(cube.vertices, corners), 6.0, 1e-12) << "inside out " << inside_out;
    // Built, its triangles face away from the centre and are one-sided.
    const auto mesh = Build(cube);
    for (const CollisionMesh::Triangle& triangle : mesh->triangles()) {
      EXPECT_FALSE(triangle.two_sided);
      EXPECT_GT(triangle.normal.dot(mesh->vertices()[triangle.vertices[0]] - Vec3(0.0, 0.0, 2.0)),
                0.0);
    }
  }
}

// An open grid with a third of its triangles reversed takes the winding of
// the other two thirds (facing +z) and is two-sided; the bin's five boxes,
// meeting at edges of four triangles, stay closed and one-sided.
TEST(MeshOrientationTest, OpenSheetTakesMajorityAndBinStaysClosed) {
  TriangleMesh grid = testing::MakeGrid(0.0, 0.0, 0.1, 6, 5, [](double, double) { return 0.0; });
  testing::ReverseTriangles([](int t) { return t % 3 == 1; }, &grid);
  const MeshOrientation orientation = OrientComponents(grid.vertices, Corners(grid));
  EXPECT_EQ(orientation.components, 1);
  const auto sheet = Build(grid);
  for (const CollisionMesh::Triangle& triangle : sheet->triangles()) {
    EXPECT_TRUE(triangle.two_sided);
    EXPECT_EQ(triangle.normal, Vec3::UnitZ());
  }
  const auto bin = Build(testing::MakeBin(Vec3(0.4, 0.3, 0.2), 0.005));
  for (const CollisionMesh::Triangle& triangle : bin->triangles()) {
    EXPECT_FALSE(triangle.two_sided);
  }
}

// A V-shaped sheet (10 degree slopes) is a valley from above and a ridge
// from below: a box pressed up 2 mm into its bottom edge from below meets
// the ridge with its top face, normal -z and depth 2 mm, which the ridge's
// convex edge region admits (taken as the valley's concave edge, it would
// be dropped and the box would pass into the sheet).
TEST(MeshOrientationTest, ValleySeenFromBelowIsARidge) {
  const double slope = std::tan(10.0 * M_PI / 180.0);
  TriangleMesh valley;
  for (const double x : {-1.0, 0.0, 1.0}) {
    for (const double y : {-1.0, 1.0}) valley.vertices.emplace_back(x, y, slope * std::abs(x));
  }
  // Vertex 2 i + j is (x_i, y_j); counter-clockwise from above.
  valley.triangles = {Eigen::Vector3i(0, 2, 3), Eigen::Vector3i(0, 3, 1), Eigen::Vector3i(2, 4, 5),
                      Eigen::Vector3i(2, 5, 3)};
  const auto mesh = Build(valley);
  const ShapeGeometry box =
      std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3::Constant(0.1)));
  const ConvexMeshPair pair{&box, Translation(0.01, 0.02, -0.048), mesh.get(), Pose::Identity(),
                            0.01};
  ContactManifold manifold;
  double gap = 0.0;
  ASSERT_TRUE(CollideConvexMeshDeepest(pair, &manifold, &gap));
  double deepest = 0.0;
  for (int i = 0; i < manifold.point_count; ++i) {
    deepest = std::min(deepest, manifold.points[i].separation);
  }
  EXPECT_NEAR(deepest, -0.002, 1e-9);
  EXPECT_NEAR(manifold.normal_world.z(), -1.0, 1e-9);
}

// A 10 cm box dropped (tilted) from `height` onto `floor` comes to rest with
// its centre at `rest_z` (m), within 1 mm; `gravity` along z.
void ExpectBoxRestsAt(const TriangleMesh& floor, double height, double gravity, double rest_z) {
  WorldSettings settings;
  settings.gravity = Vec3(0.0, 0.0, gravity);
  World world(settings);
  AddStaticMesh(&world, floor, MakeMaterial(0.5, 0.0));
  BoxSpec spec;
  spec.size = Vec3::Constant(0.1);
  spec.world_from_body = Translation(0.03, -0.02, height);
  spec.world_from_body.rotation = Quat(Eigen::AngleAxisd(0.3, Vec3(1.0, 2.0, 0.5).normalized()));
  spec.material = MakeMaterial(0.5, 0.0);
  const BodyId box = AddBox(&world, spec);
  for (int step = 0; step < 3 * 240; ++step) world.Step();
  const Body& body = world.GetBody(box);
  EXPECT_NEAR(body.position.z(), rest_z, 1e-3);
  EXPECT_LT(body.linear_velocity.norm(), 1e-3);
  std::printf("rest: z %.6f m (closed form %.6f), |v| %.3g m/s\n", body.position.z(), rest_z,
              body.linear_velocity.norm());
}

// A floor whose triangles all face down (exported upside down) holds a box
// at floor + half its height; front-side-only triangles let it fall through.
TEST(StaticMeshWorldTest, BoxRestsOnDownFacingFloor) {
  TriangleMesh floor =
      testing::MakeGrid(-0.5, -0.5, 0.1, 10, 10, [](double, double) { return 0.2; });
  testing::ReverseTriangles([](int) { return true; }, &floor);
  ExpectBoxRestsAt(floor, 0.5, -9.81, 0.25);
}

// A box falling upwards (gravity reversed) onto the floor sheet from below
// stops with its top at the sheet, its centre half its height below.
TEST(StaticMeshWorldTest, BoxRisingStopsUnderSheet) {
  const TriangleMesh sheet =
      testing::MakeGrid(-0.5, -0.5, 0.1, 10, 10, [](double, double) { return 0.2; });
  ExpectBoxRestsAt(sheet, -0.1, 9.81, 0.15);
}

// A floor with a checkerboard of reversed cells: a box rests on it at the
// same height and slides across it as over a consistent floor.
TEST(StaticMeshWorldTest, CheckerboardFloorActsAsConsistentFloor) {
  TriangleMesh checkerboard =
      testing::MakeGrid(-0.5, -0.5, 0.1, 10, 10, [](double, double) { return 0.2; });
  testing::ReverseTriangles([](int t) { return (t / 2 % 10 + t / 20) % 2 == 0; }, &checkerboard);
  ExpectBoxRestsAt(checkerboard, 0.5, -9.81, 0.25);
  TriangleMesh floor = SlidingFloor();
  testing::ReverseTriangles([](int t) { return (t / 2 % 80 + t / 160) % 2 == 0; }, &floor);
  ExpectSmoothSlide(floor);
}

// A closed block (1 x 1 x 0.2 m) whose top face and one side were exported
// reversed is wound outward when built: a box rests on its top, and the
// block stays one-sided.
TEST(StaticMeshWorldTest, BoxRestsOnClosedBlockWithReversedFaces) {
  TriangleMesh block;
  testing::AppendBox(Vec3(-0.5, -0.5, 0.0), Vec3(0.5, 0.5, 0.2), &block);
  // Triangles 10 and 11 are the top (+z), 2 and 3 the +x side.
  testing::ReverseTriangles([](int t) { return t == 2 || t == 3 || t == 10 || t == 11; }, &block);
  ExpectBoxRestsAt(block, 0.5, -9.81, 0.25);
}

}  // namespace
}  // namespace rigid_body_sim::physics
