// Rays per second of World::CastRays against Bullet's btCollisionWorld::
// rayTest on the same scene: 1,000 boxes of 0.5 m over a terrain of 99,458
// triangles (100 m square, 0.5 m waves), and 100,000 rays cast down at
// random slants from 3 m up, as a ray-cast request or a few hundred laser
// scans would cast them. Bullet's world is built once (its tree of boxes and
// the terrain's BVH), as a user of rayTest keeps it; ours builds its tree of
// shapes per batch, inside the timed call. Both find the first hit. The
// first 1,000 rays are checked against the exact first hit, computed here
// apart from both engines (the axis-aligned boxes by their slabs, the
// terrain by every triangle).
//
// Usage: ray_bench [rays]   (default 100,000); prints one line per engine
// and thread count, the errors, and the time of the fastest of ours over
// Bullet's.
#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "ray_scene.h"
#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::physics {
namespace {

using bench::kRayBox;
using bench::kRayBoxes;
using bench::kRayReach;

struct Scene {
  TriangleMesh terrain;
  std::vector<Vec3> box_centres;
  std::vector<Ray> rays;
  bench::RayScene shared;  // the same, for ExactRayDistance
};

Scene MakeScene(int ray_count) {
  Scene scene;
  scene.shared = bench::MakeRayScene(ray_count, false);
  scene.terrain.vertices = scene.shared.vertices;
  scene.terrain.triangles = scene.shared.triangles;
  scene.box_centres = scene.shared.box_centres;
  for (const bench::SceneRay& shared : scene.shared.rays) {
    Ray ray;
    ray.origin = shared.origin;
    ray.direction = shared.direction;
    ray.max_distance = kRayReach;
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
      std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3::Constant(kRayBox)));
  for (const Vec3& centre : scene.box_centres) {
    BodyDef def;
    def.world_from_body.translation = centre;
    def.mass_properties = BoxMassProperties(1000.0, Vec3::Constant(kRayBox));
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
  bullet->box = std::make_unique<btBoxShape>(btVector3(kRayBox / 2, kRayBox / 2, kRayBox / 2));
  bullet->box->setMargin(0.0);
  for (const Vec3& centre : scene.box_centres) add(bullet->box.get(), centre);
  bullet->world->updateAabbs();
  return bullet;
}

struct Accuracy {
  int rays = 0;
  int ours_disagree = 0;
  int bullet_disagree = 0;
  double ours_error = 0.0;  // m
  double bullet_error = 0.0;
};

Accuracy Compare(const Scene& scene, const std::vector<RayHit>& ours,
                 const std::vector<double>& bullet) {
  Accuracy accuracy;
  accuracy.rays = static_cast<int>(std::min<std::size_t>(1000, scene.rays.size()));
  for (int i = 0; i < accuracy.rays; ++i) {
    const double exact = bench::ExactRayDistance(scene.shared, scene.shared.rays[i], false);
    const auto score = [exact](bool hit, double distance, int* disagree, double* error) {
      if (hit != (exact >= 0.0)) {
        ++*disagree;
      } else if (hit) {
        *error = std::max(*error, std::abs(distance - exact));
      }
    };
    score(ours[i].hit, ours[i].distance, &accuracy.ours_disagree, &accuracy.ours_error);
    score(bullet[i] >= 0.0, bullet[i], &accuracy.bullet_disagree, &accuracy.bullet_error);
  }
  return accuracy;
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
              kRayBoxes, scene.terrain.triangles.size());
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
    const Accuracy accuracy = Compare(scene, hits, bullet_distances);
    std::printf("  ours CastRays, %d thread%s: %8.1f ms  %6.2f Mrays/s\n", threads,
                threads == 1 ? " " : "s", 1e3 * time, ray_count / time * 1e-6);
    if (threads == 1) {
      std::printf(
          "  against the exact first hit of the first %d rays (boxes by slabs, every "
          "triangle):\n    ours: %d hit/miss differ, largest error %.1e m; bullet: %d hit/miss "
          "differ, largest error %.1e m\n",
          accuracy.rays, accuracy.ours_disagree, accuracy.ours_error, accuracy.bullet_disagree,
          accuracy.bullet_error);
    }
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
