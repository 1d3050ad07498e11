// Rays per second of World::CastRays against Bullet's btCollisionWorld::
// rayTest on the same scene: 1,000 boxes of 0.5 m over a terrain of 99,458
// triangles (100 m square, 0.5 m waves), and 100,000 rays cast down at
// random slants from 3 m up, as a ray-cast request or a few hundred laser
// scans would cast them. Bullet's world is built once (its tree of boxes and
// the terrain's BVH), as a user of rayTest keeps it; ours builds its tree of
// shapes per batch, inside the timed call. Both find the first hit; each
// hit of ours is checked against Bullet's (its triangle test is in single
// precision, so they agree to about 1e-5 m).
//
// Usage: ray_bench [rays]   (default 100,000); prints one line per engine
// and thread count, and the ratio of the fastest of ours to Bullet's.
#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <vector>

#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::physics {
namespace {

constexpr int kCells = 223;      // terrain cells per side: 2 * 223^2 triangles
constexpr double kSize = 100.0;  // m, terrain side
constexpr int kBoxes = 1000;
constexpr double kBox = 0.5;  // m, box edge
constexpr double kMaxDistance = 100.0;

double Height(double x, double y) { return 0.5 * std::sin(0.3 * x) * std::cos(0.2 * y); }

TriangleMesh Terrain() {
  TriangleMesh mesh;
  for (int i = 0; i <= kCells; ++i) {
    for (int j = 0; j <= kCells; ++j) {
      const double x = kSize * i / kCells - kSize / 2;
      const double y = kSize * j / kCells - kSize / 2;
      mesh.vertices.emplace_back(x, y, Height(x, y));
    }
  }
  const auto index = [](int i, int j) { return i * (kCells + 1) + j; };
  for (int i = 0; i < kCells; ++i) {
    for (int j = 0; j < kCells; ++j) {
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j), index(i + 1, j + 1));
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j + 1), index(i, j + 1));
    }
  }
  return mesh;
}

struct Scene {
  TriangleMesh terrain;
  std::vector<Vec3> box_centres;
  std::vector<Ray> rays;
};

Scene MakeScene(int ray_count) {
  Scene scene;
  scene.terrain = Terrain();
  std::mt19937 random(3);
  std::uniform_real_distribution<double> place(-40.0, 40.0);
  for (int i = 0; i < kBoxes; ++i)
    scene.box_centres.emplace_back(place(random), place(random), 1.5);
  for (int k = 0; k < ray_count; ++k) {
    Ray ray;
    ray.origin = Vec3(place(random), place(random), 3.0);
    ray.direction = Vec3(place(random), place(random), -40.0).normalized();
    ray.max_distance = kMaxDistance;
    scene.rays.push_back(ray);
  }
  return scene;
}

World MakeOurWorld(const Scene& scene, int threads) {
  WorldSettings settings;
  settings.threads = threads;
  World world(settings);
  BodyDef ground;
  ground.is_static = true;
  ShapeDef mesh;
  mesh.geometry = StaticMesh{CollisionMesh::Make(scene.terrain).value()};
  ground.shapes.push_back(mesh);
  world.CreateBody(ground).value();
  const auto box =
      std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3::Constant(kBox)));
  for (const Vec3& centre : scene.box_centres) {
    BodyDef def;
    def.world_from_body.translation = centre;
    def.mass_properties = BoxMassProperties(1000.0, Vec3::Constant(kBox));
    ShapeDef shape;
    shape.geometry = box;
    def.shapes.push_back(shape);
    world.CreateBody(def).value();
  }
  return world;
}

// Bullet's collision world of the same shapes, kept alive together.
struct BulletScene {
  std::unique_ptr<btDefaultCollisionConfiguration> configuration;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btCollisionWorld> world;
  std::unique_ptr<btTriangleMesh> triangles;
  std::unique_ptr<btBvhTriangleMeshShape> terrain;
  std::unique_ptr<btBoxShape> box;
  std::vector<std::unique_ptr<btCollisionObject>> objects;
};

btVector3 ToBullet(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }

std::unique_ptr<BulletScene> MakeBulletScene(const Scene& scene) {
  auto bullet = std::make_unique<BulletScene>();
  bullet->configuration = std::make_unique<btDefaultCollisionConfiguration>();
  bullet->dispatcher = std::make_unique<btCollisionDispatcher>(bullet->configuration.get());
  bullet->broadphase = std::make_unique<btDbvtBroadphase>();
  bullet->world = std::make_unique<btCollisionWorld>(
      bullet->dispatcher.get(), bullet->broadphase.get(), bullet->configuration.get());
  bullet->triangles = std::make_unique<btTriangleMesh>();
  for (const auto& triangle : scene.terrain.triangles) {
    bullet->triangles->addTriangle(ToBullet(scene.terrain.vertices[triangle[0]]),
                                   ToBullet(scene.terrain.vertices[triangle[1]]),
                                   ToBullet(scene.terrain.vertices[triangle[2]]));
  }
  bullet->terrain = std::make_unique<btBvhTriangleMeshShape>(bullet->triangles.get(), true);
  auto add = [&](btCollisionShape* shape, const Vec3& position) {
    auto object = std::make_unique<btCollisionObject>();
    object->setCollisionShape(shape);
    btTransform transform;
    transform.setIdentity();
    transform.setOrigin(ToBullet(position));
    object->setWorldTransform(transform);
    bullet->world->addCollisionObject(object.get());
    bullet->objects.push_back(std::move(object));
  };
  add(bullet->terrain.get(), Vec3::Zero());
  // Bullet's margin rounds a box's edges; 0 keeps its faces where ours are.
  bullet->box = std::make_unique<btBoxShape>(btVector3(kBox / 2, kBox / 2, kBox / 2));
  bullet->box->setMargin(0.0);
  for (const Vec3& centre : scene.box_centres) add(bullet->box.get(), centre);
  bullet->world->updateAabbs();
  return bullet;
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The best of three runs: the others share the machine.
double TimeOurs(const World& world, const Scene& scene, std::vector<RayHit>* hits) {
  double best = 1e30;
  for (int run = 0; run < 3; ++run) {
    const auto start = std::chrono::steady_clock::now();
    *hits = world.CastRays(scene.rays).value();
    best = std::min(best, Seconds(start));
  }
  return best;
}

double TimeBullet(const BulletScene& bullet, const Scene& scene, std::vector<double>* distances) {
  double best = 1e30;
  for (int run = 0; run < 3; ++run) {
    distances->assign(scene.rays.size(), -1.0);
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < scene.rays.size(); ++i) {
      const Ray& ray = scene.rays[i];
      const btVector3 from = ToBullet(ray.origin);
      const btVector3 to = ToBullet(ray.origin + ray.max_distance * ray.direction);
      btCollisionWorld::ClosestRayResultCallback callback(from, to);
      bullet.world->rayTest(from, to, callback);
      if (callback.hasHit()) (*distances)[i] = callback.m_closestHitFraction * ray.max_distance;
    }
    best = std::min(best, Seconds(start));
  }
  return best;
}

int Run(int ray_count) {
  const Scene scene = MakeScene(ray_count);
  std::printf("[ray] %d rays, %d boxes, %zu terrain triangles (best of 3 runs)\n", ray_count,
              kBoxes, scene.terrain.triangles.size());
  const std::unique_ptr<BulletScene> bullet = MakeBulletScene(scene);
  std::vector<double> bullet_distances;
  const double bullet_time = TimeBullet(*bullet, scene, &bullet_distances);
  std::printf("  bullet rayTest, 1 thread:  %8.1f ms  %6.2f Mrays/s\n", 1e3 * bullet_time,
              ray_count / bullet_time * 1e-6);
  double best_ours = 1e30;
  for (const int threads : {1, 2}) {
    const World world = MakeOurWorld(scene, threads);
    std::vector<RayHit> hits;
    const double time = TimeOurs(world, scene, &hits);
    best_ours = std::min(best_ours, time);
    int disagree = 0;
    double worst = 0.0;
    for (std::size_t i = 0; i < hits.size(); ++i) {
      const bool bullet_hit = bullet_distances[i] >= 0.0;
      if (hits[i].hit != bullet_hit) {
        ++disagree;
      } else if (bullet_hit) {
        worst = std::max(worst, std::abs(hits[i].distance - bullet_distances[i]));
      }
    }
    std::printf(
        "  ours CastRays, %d thread%s: %8.1f ms  %6.2f Mrays/s  (hit/miss differs on %d rays, "
        "largest distance difference %.1e m)\n",
        threads, threads == 1 ? " " : "s", 1e3 * time, ray_count / time * 1e-6, disagree, worst);
  }
  std::printf("  ours / bullet time: %.2f\n", best_ours / bullet_time);
  return 0;
}

}  // namespace
}  // namespace rigid_body_sim::physics

int main(int argc, char** argv) {
  const int rays = argc > 1 ? std::max(1, std::atoi(argv[1])) : 100000;
  return rigid_body_sim::physics::Run(rays);
}
