// ray_bench's scene, shared by ray_bench.cc (the core against Bullet) and
// ray_service_client.cc (the same scene and rays through the node), so that
// both draw the same numbers in the same order: 1,000 boxes of 0.5 m over a
// terrain of 99,458 triangles (100 m square, 0.5 m waves), and rays cast
// down at random slants from 3 m up. Eigen and std only.
#ifndef RIGID_BODY_SIM_BENCH_RAY_SCENE_H_
#define RIGID_BODY_SIM_BENCH_RAY_SCENE_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace rigid_body_sim::bench {

constexpr int kRayCells = 223;         // terrain cells per side: 2 * 223^2 triangles
constexpr double kRayTerrain = 100.0;  // m, terrain side
constexpr int kRayBoxes = 1000;
constexpr double kRayBox = 0.5;      // m, box edge
constexpr double kRayReach = 100.0;  // m, each ray's max_distance

struct SceneRay {
  Eigen::Vector3d origin;     // m, world
  Eigen::Vector3d direction;  // unit
};

struct RayScene {
  std::vector<Eigen::Vector3d> vertices;  // m, the terrain's
  std::vector<Eigen::Vector3i> triangles;
  std::vector<Eigen::Vector3d> box_centres;  // m, axis-aligned boxes of kRayBox
  std::vector<SceneRay> rays;
};

inline double RayTerrainHeight(double x, double y) {
  return 0.5 * std::sin(0.3 * x) * std::cos(0.2 * y);
}

// With `float_vertices`, each terrain vertex is rounded to float, as a binary
// STL file holds it.
inline RayScene MakeRayScene(int ray_count, bool float_vertices) {
  RayScene scene;
  for (int i = 0; i <= kRayCells; ++i) {
    for (int j = 0; j <= kRayCells; ++j) {
      const double x = kRayTerrain * i / kRayCells - kRayTerrain / 2;
      const double y = kRayTerrain * j / kRayCells - kRayTerrain / 2;
      const Eigen::Vector3d vertex(x, y, RayTerrainHeight(x, y));
      scene.vertices.push_back(float_vertices ? vertex.cast<float>().cast<double>() : vertex);
    }
  }
  const auto index = [](int i, int j) { return i * (kRayCells + 1) + j; };
  for (int i = 0; i < kRayCells; ++i) {
    for (int j = 0; j < kRayCells; ++j) {
      scene.triangles.emplace_back(index(i, j), index(i + 1, j), index(i + 1, j + 1));
      scene.triangles.emplace_back(index(i, j), index(i + 1, j + 1), index(i, j + 1));
    }
  }
  std::mt19937 random(3);
  std::uniform_real_distribution<double> place(-40.0, 40.0);
  // One draw per statement, y before x: the order in which the first
  // version's calls drew them (GCC's, right to left), so that the scene is
  // the one the recorded figures were measured on.
  for (int k = 0; k < kRayBoxes; ++k) {
    const double y = place(random);
    const double x = place(random);
    scene.box_centres.emplace_back(x, y, 1.5);
  }
  for (int k = 0; k < ray_count; ++k) {
    const double y = place(random);
    const double x = place(random);
    const double dy = place(random);
    const double dx = place(random);
    scene.rays.push_back({Eigen::Vector3d(x, y, 3.0), Eigen::Vector3d(dx, dy, -40.0).normalized()});
  }
  return scene;
}

// The exact first hit within kRayReach, apart from any engine: the boxes by
// their slabs, the terrain by every triangle (Moller and Trumbore 1997,
// "Fast, Minimum Storage Ray/Triangle Intersection", J. Graphics Tools
// 2(1)), and with `ground` the plane z = 0 from above; -1 for none.
inline double ExactRayDistance(const RayScene& scene, const SceneRay& ray, bool ground) {
  double best = kRayReach;
  bool hit = false;
  const auto take = [&](double t) {
    if (t >= 0.0 && t <= best) {
      best = t;
      hit = true;
    }
  };
  for (const Eigen::Vector3d& centre : scene.box_centres) {
    double enter = 0.0;
    double exit = kRayReach;
    for (int axis = 0; axis < 3; ++axis) {
      const double low = (centre[axis] - kRayBox / 2 - ray.origin[axis]) / ray.direction[axis];
      const double high = (centre[axis] + kRayBox / 2 - ray.origin[axis]) / ray.direction[axis];
      enter = std::max(enter, std::min(low, high));
      exit = std::min(exit, std::max(low, high));
    }
    if (enter <= exit) take(enter);
  }
  for (const Eigen::Vector3i& triangle : scene.triangles) {
    const Eigen::Vector3d& a = scene.vertices[triangle[0]];
    const Eigen::Vector3d e1 = scene.vertices[triangle[1]] - a;
    const Eigen::Vector3d e2 = scene.vertices[triangle[2]] - a;
    const Eigen::Vector3d p = ray.direction.cross(e2);
    const double det = e1.dot(p);
    if (det == 0.0) continue;
    const Eigen::Vector3d s = ray.origin - a;
    const double u = s.dot(p) / det;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = ray.direction.dot(q) / det;
    if (u >= 0.0 && v >= 0.0 && u + v <= 1.0) take(e2.dot(q) / det);
  }
  if (ground && ray.origin.z() >= 0.0 && ray.direction.z() < 0.0) {
    take(-ray.origin.z() / ray.direction.z());
  }
  return hit ? best : -1.0;
}

}  // namespace rigid_body_sim::bench

#endif  // RIGID_BODY_SIM_BENCH_RAY_SCENE_H_
