// Ray casts against closed forms (sphere, box, cylinder caps and side, the
// ground), a static mesh's tree walk against testing every triangle, and
// World::CastRays through its shape tree against casting every shape of
// every body, on one thread and on two.
#include "physics/collision/ray_cast.h"

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "rigid_body_sim/physics/world.h"
#include "scene.h"

namespace rigid_body_sim::physics::testing {
namespace {

Ray MakeRay(const Vec3& origin, const Vec3& direction, double max_distance = 100.0) {
  return Ray{origin, direction.normalized(), max_distance};
}

World MakeWorldWithThreads(int threads) {
  WorldSettings settings;
  settings.threads = threads;
  return World(settings);
}

TEST(RayCastTest, SphereHitMatchesTheClosedForm) {
  // A sphere of r = 0.5 at (3, 0.2, 0.1), a ray from the origin along x:
  // t = 3 - sqrt(r^2 - 0.2^2 - 0.1^2).
  const Pose world_from_sphere = Translation(3.0, 0.2, 0.1);
  const RayHit hit =
      RayCastShape(Sphere{0.5}, world_from_sphere, MakeRay(Vec3::Zero(), Vec3::UnitX()));
  ASSERT_TRUE(hit.hit);
  EXPECT_NEAR(hit.distance, 3.0 - std::sqrt(0.2), 1e-14);
  EXPECT_NEAR((hit.normal - (hit.point - Vec3(3.0, 0.2, 0.1)) / 0.5).norm(), 0.0, 1e-14);
  // Far away the digits stay: 1e4 m along the ray.
  const RayHit far = RayCastShape(Sphere{0.5}, Translation(1e4, 0.2, 0.1),
                                  MakeRay(Vec3::Zero(), Vec3::UnitX(), 2e4));
  EXPECT_NEAR(far.distance, 1e4 - std::sqrt(0.2), 1e-11);
  // From inside, the sphere is not hit; past the ray's length neither.
  EXPECT_FALSE(
      RayCastShape(Sphere{0.5}, Translation(0.1, 0, 0), MakeRay(Vec3::Zero(), Vec3::UnitX())).hit);
  EXPECT_FALSE(
      RayCastShape(Sphere{0.5}, world_from_sphere, MakeRay(Vec3::Zero(), Vec3::UnitX(), 2.5)).hit);
}

TEST(RayCastTest, RotatedBoxIsEnteredThroughTheFaceTheGeometryPredicts) {
  // A 1 x 2 x 0.5 box turned 30 degrees about z at c = (4, 0, 0): a ray
  // along x at y = 0.1 enters its face whose normal n is -x turned by 30
  // degrees, the plane n . (p - c) = 0.5 (half the 1 m edge).
  const auto box = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3(1.0, 2.0, 0.5)));
  const double angle = M_PI / 6.0;
  Pose world_from_box = Translation(4.0, 0.0, 0.0);
  world_from_box.rotation = Quat(Eigen::AngleAxisd(angle, Vec3::UnitZ()));
  const Vec3 origin(0.0, 0.1, 0.0);
  const RayHit hit = RayCastShape(box, world_from_box, MakeRay(origin, Vec3::UnitX()));
  ASSERT_TRUE(hit.hit);
  const Vec3 normal = world_from_box.rotation * Vec3(-1.0, 0.0, 0.0);
  // n . (o + t x - c) = 0.5  =>  t = (0.5 - n . (o - c)) / n.x
  const double t = (0.5 - normal.dot(origin - world_from_box.translation)) / normal.x();
  EXPECT_NEAR(hit.distance, t, 1e-13);
  EXPECT_NEAR((hit.normal - normal).norm(), 0.0, 1e-13);
}

TEST(RayCastTest, CylinderIsEnteredThroughItsSideOrItsCap) {
  const Cylinder cylinder{0.3, 0.5};  // r, half length along z
  const Pose at = Translation(2.0, 0.0, 0.0);
  // Along x at height 0.2, offset 0.1 in y: the side, t = 2 - sqrt(r^2 - 0.1^2).
  const RayHit side = RayCastShape(cylinder, at, MakeRay(Vec3(0, 0.1, 0.2), Vec3::UnitX()));
  ASSERT_TRUE(side.hit);
  EXPECT_NEAR(side.distance, 2.0 - std::sqrt(0.09 - 0.01), 1e-14);
  EXPECT_NEAR(side.normal.z(), 0.0, 1e-15);
  // Straight down from z = 3 at 0.2 from the axis: the top cap, t = 2.5.
  const RayHit cap = RayCastShape(cylinder, at, MakeRay(Vec3(2.2, 0, 3.0), -Vec3::UnitZ()));
  ASSERT_TRUE(cap.hit);
  EXPECT_NEAR(cap.distance, 2.5, 1e-14);
  EXPECT_NEAR((cap.normal - Vec3::UnitZ()).norm(), 0.0, 1e-15);
  // Down at 0.31 from the axis: it passes the cap's rim.
  EXPECT_FALSE(RayCastShape(cylinder, at, MakeRay(Vec3(2.31, 0, 3.0), -Vec3::UnitZ())).hit);
}

TEST(RayCastTest, GroundIsHitFromAboveOnly) {
  const RayHit hit =
      RayCastShape(HalfSpace{}, Pose::Identity(), MakeRay(Vec3(0, 0, 2), Vec3(1, 0, -1)));
  ASSERT_TRUE(hit.hit);
  EXPECT_NEAR(hit.distance, 2.0 * std::sqrt(2.0), 1e-14);
  EXPECT_FALSE(
      RayCastShape(HalfSpace{}, Pose::Identity(), MakeRay(Vec3(0, 0, 2), Vec3::UnitZ())).hit);
  EXPECT_FALSE(
      RayCastShape(HalfSpace{}, Pose::Identity(), MakeRay(Vec3(0, 0, -1), -Vec3::UnitZ())).hit);
}

// A 60 x 60 terrain of 7,200 triangles with a bumpy height.
std::shared_ptr<const CollisionMesh> Terrain(double size, int cells) {
  TriangleMesh mesh;
  for (int i = 0; i <= cells; ++i) {
    for (int j = 0; j <= cells; ++j) {
      const double x = size * i / cells - size / 2;
      const double y = size * j / cells - size / 2;
      mesh.vertices.emplace_back(x, y, 0.3 * std::sin(0.7 * x) * std::cos(0.5 * y));
    }
  }
  const auto index = [cells](int i, int j) { return i * (cells + 1) + j; };
  for (int i = 0; i < cells; ++i) {
    for (int j = 0; j < cells; ++j) {
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j), index(i + 1, j + 1));
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j + 1), index(i, j + 1));
    }
  }
  return CollisionMesh::Make(mesh).value();
}

TEST(RayCastTest, MeshTreeWalkMatchesEveryTriangle) {
  const std::shared_ptr<const CollisionMesh> terrain = Terrain(20.0, 60);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-12.0, 12.0);
  int hits = 0;
  for (int k = 0; k < 3000; ++k) {
    const Vec3 origin(coordinate(random), coordinate(random), 0.5 * coordinate(random));
    const Vec3 target(coordinate(random), coordinate(random), 0.0);
    if ((target - origin).norm() < 1e-6) continue;
    const Ray ray = MakeRay(origin, target - origin, 30.0);
    const RayHit tree = RayCastMesh(*terrain, ray);
    const RayHit brute = RayCastMeshBruteForce(*terrain, ray);
    ASSERT_EQ(tree.hit, brute.hit) << k;
    if (!tree.hit) continue;
    ++hits;
    ASSERT_EQ(tree.distance, brute.distance) << k;
    ASSERT_EQ(tree.normal, brute.normal) << k;
  }
  EXPECT_GT(hits, 1000);
}

// A world of random spheres, boxes, cylinders and hulls over the ground
// and a terrain, and the reference: every shape of every body cast.
class RayWorldTest : public ::testing::Test {
 protected:
  void Build(World* world) {
    std::mt19937 random(11);
    std::uniform_real_distribution<double> position(-8.0, 8.0);
    std::uniform_real_distribution<double> size(0.1, 0.8);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    BodyDef ground;
    ground.is_static = true;
    ShapeDef half_space;
    half_space.geometry = HalfSpace{};
    ground.shapes.push_back(half_space);
    Add(world, ground);
    BodyDef terrain;
    terrain.is_static = true;
    terrain.world_from_body = Translation(0, 0, 0.5);
    ShapeDef mesh;
    mesh.geometry = StaticMesh{Terrain(20.0, 40)};
    terrain.shapes.push_back(mesh);
    Add(world, terrain);
    for (int i = 0; i < 300; ++i) {
      BodyDef def;
      def.world_from_body =
          Translation(position(random), position(random), 1.0 + 0.5 * position(random));
      def.world_from_body.rotation =
          Quat(unit(random), unit(random), unit(random), unit(random)).normalized();
      def.mass_properties = SphereMassProperties(1000.0, 0.3);
      ShapeDef shape;
      switch (i % 4) {
        case 0:
          shape.geometry = Sphere{size(random)};
          break;
        case 1:
          shape.geometry = std::make_shared<const ConvexPolyhedron>(
              MakeBoxPolyhedron(Vec3(size(random), size(random), size(random))));
          break;
        case 2:
          shape.geometry = Cylinder{size(random), size(random)};
          break;
        default:
          shape.geometry = std::make_shared<const ConvexPolyhedron>(
              TryMakeCylinderPolyhedron(size(random), size(random), 7).value());
      }
      shape.body_from_shape = Translation(0.1 * unit(random), 0.0, 0.1 * unit(random));
      def.shapes.push_back(shape);
      if (i % 5 == 0) {
        ShapeDef second;
        second.geometry = Sphere{0.2};
        second.body_from_shape = Translation(0.4, 0.0, 0.0);
        def.shapes.push_back(second);
      }
      Add(world, def);
    }
  }

  void Add(World* world, const BodyDef& def) {
    ids_.push_back(world->CreateBody(def).value());
    defs_.push_back(def);
  }

  RayHit Reference(const World& world, const Ray& ray) const {
    RayHit best;
    for (std::size_t b = 0; b < ids_.size(); ++b) {
      const Pose world_from_body = world.GetPose(ids_[b]);
      for (std::size_t s = 0; s < defs_[b].shapes.size(); ++s) {
        const ShapeDef& shape = defs_[b].shapes[s];
        const Pose world_from_shape = world_from_body * shape.body_from_shape;
        RayHit hit;
        if (const auto* mesh = std::get_if<StaticMesh>(&shape.geometry)) {
          Ray local = ray;
          local.origin =
              world_from_shape.rotation.conjugate() * (ray.origin - world_from_shape.translation);
          local.direction = world_from_shape.rotation.conjugate() * ray.direction;
          hit = RayCastMeshBruteForce(*mesh->mesh, local);
          hit.point = ray.origin + hit.distance * ray.direction;
          hit.normal = world_from_shape.rotation * hit.normal;
        } else {
          hit = RayCastShape(shape.geometry, world_from_shape, ray);
        }
        if (hit.hit && (!best.hit || hit.distance < best.distance)) {
          best = hit;
          best.body = ids_[b];
          best.shape = static_cast<int>(s);
        }
      }
    }
    return best;
  }

  std::vector<Ray> RandomRays(int count) const {
    std::mt19937 random(5);
    std::uniform_real_distribution<double> position(-10.0, 10.0);
    std::vector<Ray> rays;
    for (int k = 0; k < count; ++k) {
      const Vec3 origin(position(random), position(random), 2.0 + 0.5 * position(random));
      const Vec3 direction(position(random), position(random), position(random));
      rays.push_back(MakeRay(origin, direction, 25.0));
    }
    return rays;
  }

  std::vector<BodyId> ids_;
  std::vector<BodyDef> defs_;
};

TEST_F(RayWorldTest, ShapeTreeMatchesCastingEveryShape) {
  World world = MakeWorldWithThreads(1);
  Build(&world);
  const std::vector<Ray> rays = RandomRays(4000);
  const std::vector<RayHit> hits = world.CastRays(rays).value();
  int hit_count = 0;
  for (std::size_t k = 0; k < rays.size(); ++k) {
    const RayHit reference = Reference(world, rays[k]);
    ASSERT_EQ(hits[k].hit, reference.hit) << k;
    if (!reference.hit) continue;
    ++hit_count;
    ASSERT_NEAR(hits[k].distance, reference.distance, 1e-9) << k;
    ASSERT_EQ(hits[k].body, reference.body) << k;
    ASSERT_EQ(hits[k].shape, reference.shape) << k;
    ASSERT_NEAR((hits[k].point - (rays[k].origin + reference.distance * rays[k].direction)).norm(),
                0.0, 1e-9);
  }
  EXPECT_GT(hit_count, 2000);
}

TEST_F(RayWorldTest, TwoThreadsGiveTheOneThreadHitsBitForBit) {
  World one = MakeWorldWithThreads(1);
  Build(&one);
  World two = MakeWorldWithThreads(2);
  ids_.clear();
  defs_.clear();
  Build(&two);
  const std::vector<Ray> rays = RandomRays(3000);
  const std::vector<RayHit> a = one.CastRays(rays).value();
  const std::vector<RayHit> b = two.CastRays(rays).value();
  for (std::size_t k = 0; k < rays.size(); ++k) {
    ASSERT_EQ(a[k].hit, b[k].hit);
    ASSERT_EQ(a[k].distance, b[k].distance);
    ASSERT_EQ(a[k].normal, b[k].normal);
  }
}

TEST_F(RayWorldTest, IgnoredBodiesAreSeenThrough) {
  World world = MakeWorldWithThreads(1);
  const BodyId front = AddSphere(&world, {0.5, 1.0, Translation(2, 0, 1), Vec3::Zero(), {}});
  const BodyId back = AddSphere(&world, {0.5, 1.0, Translation(5, 0, 1), Vec3::Zero(), {}});
  const Ray ray = MakeRay(Vec3(0, 0, 1), Vec3::UnitX());
  EXPECT_EQ(world.CastRays({ray}).value()[0].body, front);
  const RayHit behind = world.CastRays({ray}, {front}).value()[0];
  EXPECT_EQ(behind.body, back);
  EXPECT_NEAR(behind.distance, 4.5, 1e-14);
}

TEST_F(RayWorldTest, BadRaysAreRefusedWhole) {
  World world = MakeWorldWithThreads(1);
  std::vector<Ray> rays(5, MakeRay(Vec3::Zero(), Vec3::UnitX()));
  rays[3].origin.x() = std::nan("");
  Result<std::vector<RayHit>> result = world.CastRays(rays);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("ray 3"), std::string::npos);
  rays[3] = MakeRay(Vec3::Zero(), Vec3::UnitX());
  rays[1].direction = Vec3(0, 0, 2);
  result = world.CastRays(rays);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("ray 1: direction"), std::string::npos);
  rays[1] = MakeRay(Vec3::Zero(), Vec3::UnitX());
  rays[2].max_distance = -1.0;
  EXPECT_FALSE(world.CastRays(rays).ok());
}

}  // namespace
}  // namespace rigid_body_sim::physics::testing
