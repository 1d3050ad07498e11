// Times loading a 1 MB binary STL and hulling its vertices, the path every
// mesh collision element of a URDF takes. Not a test: it prints the times.
//
// The mesh is a triangle soup of 20,000 triangles (84 + 50 * 20,000 bytes)
// whose 60,000 corners are points of an ellipsoid with 1 % radial noise, each
// corner distinct, so qhull sees 60,000 points of which most lie near the
// hull and simplification to 256 vertices has real work to do.
//
// Usage: hull_bench [path.stl]   (without a path a generated mesh is used)

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "rigid_body_sim/io/convex_hull.h"
#include "rigid_body_sim/io/mesh_loader.h"

namespace {

using rigid_body_sim::physics::Vec3;

constexpr int kTriangles = 20000;
constexpr int kRepetitions = 5;

void WriteFloat(std::ofstream& out, float value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(value));
}

// Random directions scaled onto an ellipsoid with semi-axes 0.3, 0.2, 0.1 m.
std::string WriteNoisyEllipsoidStl() {
  const std::string path =
      (std::filesystem::temp_directory_path() / "rigid_body_sim_hull_bench.stl").string();
  std::ofstream out(path, std::ios::binary);
  const std::string header(80, ' ');
  out.write(header.data(), header.size());
  const std::uint32_t count = kTriangles;
  out.write(reinterpret_cast<const char*>(&count), sizeof(count));
  std::mt19937_64 random(42);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> noise(0.99, 1.01);
  const Vec3 semi_axes(0.3, 0.2, 0.1);
  for (int t = 0; t < kTriangles; ++t) {
    const Vec3 center = Vec3(normal(random), normal(random), normal(random)).normalized();
    for (int k = 0; k < 3; ++k) WriteFloat(out, static_cast<float>(center[k]));
    for (int corner = 0; corner < 3; ++corner) {
      const Vec3 jitter(normal(random), normal(random), normal(random));
      const Vec3 direction = (center + 0.02 * jitter).normalized();
      const Vec3 point = noise(random) * direction.cwiseProduct(semi_axes);
      for (int k = 0; k < 3; ++k) WriteFloat(out, static_cast<float>(point[k]));
    }
    const std::uint16_t attributes = 0;
    out.write(reinterpret_cast<const char*>(&attributes), sizeof(attributes));
  }
  return path;
}

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : WriteNoisyEllipsoidStl();
  std::printf("mesh: %s (%.2f MB)\n", path.c_str(),
              static_cast<double>(std::filesystem::file_size(path)) / 1e6);
  double best_load = 1e300;
  double best_hull = 1e300;
  for (int repetition = 0; repetition < kRepetitions; ++repetition) {
    const auto load_start = std::chrono::steady_clock::now();
    const auto mesh = rigid_body_sim::io::LoadMesh(path);
    const double load_ms = MillisecondsSince(load_start);
    if (!mesh.ok()) {
      std::fprintf(stderr, "load failed: %s\n", mesh.message().c_str());
      return 1;
    }
    const auto hull_start = std::chrono::steady_clock::now();
    const auto hull = rigid_body_sim::io::ComputeConvexHull(mesh->vertices);
    const double hull_ms = MillisecondsSince(hull_start);
    if (!hull.ok()) {
      std::fprintf(stderr, "hull failed: %s\n", hull.message().c_str());
      return 1;
    }
    if (repetition == 0) {
      std::printf("vertices: %zu, triangles: %zu, hull vertices: %zu, hull faces: %zu\n",
                  mesh->vertices.size(), mesh->triangles.size(), hull->vertices.size(),
                  hull->faces.size());
    }
    best_load = std::min(best_load, load_ms);
    best_hull = std::min(best_hull, hull_ms);
  }
  std::printf("best of %d: load %.1f ms, hull %.1f ms, total %.1f ms\n", kRepetitions, best_load,
              best_hull, best_load + best_hull);
  return 0;
}
