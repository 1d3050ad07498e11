// Times the sort-and-sweep broad phase on coherent motion, for 1k, 10k and 50k
// boxes in a cube whose side grows with the body count, so that the density
// (and the number of pairs per body) stays the same.
//
// The incremental update costs O(n + s), n endpoints scanned and s adjacent
// swaps. Two scenes show both terms:
//  - "drift": every box moves at up to 1 m/s (1.7 cm per step). At a fixed
//    density the endpoints projected on an axis get closer as the cube grows
//    (n / side ~ n^(2/3) per metre), so a box passes ~n^(2/3) endpoints per
//    step and s grows like n^(5/3);
//  - "jitter": resting boxes that shake by up to 0.1 mm per step around their
//    rest positions, as a settled pile does under the solver; s stays small
//    and the update is dominated by the linear scan.
// The printed ns per (endpoint + swap) should stay roughly flat in both.
//
// Usage: broad_phase_bench [steps]   (default 100 timed steps per case)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "physics/collision/broad_phase.h"

namespace rigid_body_sim::physics {
namespace {

constexpr double kDensity = 2.0;    // boxes per m^3
constexpr double kMinSize = 0.25;   // m, box side
constexpr double kMaxSize = 0.75;   // m, box side
constexpr double kDt = 1.0 / 60.0;  // s
constexpr int kWarmupSteps = 10;

struct Scene {
  const char* name;
  double max_speed;   // m/s per axis, drifting boxes
  double max_jitter;  // m per axis, displacement from the rest position
};

struct MovingBox {
  Vec3 rest_corner;  // m, min corner
  Vec3 min_corner;   // m
  Vec3 size;         // m
  Vec3 velocity;     // m/s
};

struct Timing {
  double build_ms = 0.0;    // first Update(): full sort and sweep
  double update_ms = 0.0;   // per step: SetAabb for every box, then Update()
  double pairs_ms = 0.0;    // per step: Pairs(), sorted
  double mean_pairs = 0.0;  // per step
  double mean_swaps = 0.0;  // adjacent endpoint swaps per Update(), all axes
};

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

Timing Run(const Scene& scene, int body_count, int steps, std::mt19937_64& rng) {
  const double region = std::cbrt(body_count / kDensity);  // m, cube side
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto symmetric = [&]() { return 2.0 * unit(rng) - 1.0; };
  std::vector<MovingBox> boxes(body_count);
  SortAndSweepBroadPhase broad_phase;
  std::vector<int> ids(body_count);
  for (int i = 0; i < body_count; ++i) {
    MovingBox& box = boxes[i];
    for (int axis = 0; axis < 3; ++axis) {
      box.size[axis] = kMinSize + (kMaxSize - kMinSize) * unit(rng);
      box.rest_corner[axis] = (region - box.size[axis]) * unit(rng);
      box.velocity[axis] = scene.max_speed * symmetric();
    }
    box.min_corner = box.rest_corner;
    ids[i] =
        broad_phase.AddProxy(Aabb{box.min_corner, box.min_corner + box.size}, ProxyKind::kDynamic)
            .value();
  }
  Timing timing;
  auto start = std::chrono::steady_clock::now();
  broad_phase.Update();
  timing.build_ms = MillisecondsSince(start);

  std::vector<Aabb> next(body_count);
  double pair_sum = 0.0;
  double swap_sum = 0.0;
  for (int step = 0; step < kWarmupSteps + steps; ++step) {
    for (int i = 0; i < body_count; ++i) {
      MovingBox& box = boxes[i];
      for (int axis = 0; axis < 3; ++axis) {
        // Drift with a small random change of velocity, reflecting at the
        // walls, plus a shake around the rest position.
        box.velocity[axis] = std::clamp(box.velocity[axis] + 0.1 * scene.max_speed * symmetric(),
                                        -scene.max_speed, scene.max_speed);
        double position = box.rest_corner[axis] + box.velocity[axis] * kDt;
        const double limit = region - box.size[axis];
        if (position < 0.0 || position > limit) {
          box.velocity[axis] = -box.velocity[axis];
          position = std::clamp(position, 0.0, limit);
        }
        box.rest_corner[axis] = position;
        box.min_corner[axis] = position + scene.max_jitter * symmetric();
      }
      next[i] = Aabb{box.min_corner, box.min_corner + box.size};
    }
    const bool timed = step >= kWarmupSteps;
    start = std::chrono::steady_clock::now();
    for (int i = 0; i < body_count; ++i) {
      if (!broad_phase.SetAabb(ids[i], next[i]).ok()) {
        std::fprintf(stderr, "SetAabb refused box %d\n", i);
        std::exit(1);
      }
    }
    broad_phase.Update();
    const double update_ms = MillisecondsSince(start);
    start = std::chrono::steady_clock::now();
    const std::vector<ProxyPair> pairs = broad_phase.Pairs();
    const double pairs_ms = MillisecondsSince(start);
    if (timed) {
      timing.update_ms += update_ms;
      timing.pairs_ms += pairs_ms;
      pair_sum += static_cast<double>(pairs.size());
      swap_sum += static_cast<double>(broad_phase.last_update_swaps());
    }
  }
  timing.update_ms /= steps;
  timing.pairs_ms /= steps;
  timing.mean_pairs = pair_sum / steps;
  timing.mean_swaps = swap_sum / steps;
  return timing;
}

}  // namespace
}  // namespace rigid_body_sim::physics

int main(int argc, char** argv) {
  using rigid_body_sim::physics::Run;
  using rigid_body_sim::physics::Scene;
  using rigid_body_sim::physics::Timing;
  const int steps = argc > 1 ? std::max(1, std::atoi(argv[1])) : 100;
  const Scene kScenes[] = {{"drift", 1.0, 0.0}, {"jitter", 0.0, 1e-4}};
  const int kCounts[] = {1000, 10000, 50000};
  std::printf("sort-and-sweep broad phase, %d timed steps per case\n", steps);
  std::printf("%-7s %7s %8s %11s %10s %11s %11s %13s  %s\n", "scene", "bodies", "pairs",
              "swaps/step", "build ms", "update ms", "Pairs() ms", "ns/(ep+swap)", "update growth");
  for (const Scene& scene : kScenes) {
    std::mt19937_64 rng(12345);
    double previous_ms = 0.0;
    int previous_count = 0;
    for (int count : kCounts) {
      const Timing timing = Run(scene, count, steps, rng);
      const double endpoints = 6.0 * count;
      const double ns_per_unit = 1e6 * timing.update_ms / (endpoints + timing.mean_swaps);
      std::printf("%-7s %7d %8.0f %11.0f %10.3f %11.4f %11.4f %13.2f", scene.name, count,
                  timing.mean_pairs, timing.mean_swaps, timing.build_ms, timing.update_ms,
                  timing.pairs_ms, ns_per_unit);
      if (previous_count > 0) {
        std::printf("  x%.2f for x%.0f bodies", timing.update_ms / previous_ms,
                    static_cast<double>(count) / previous_count);
      }
      std::printf("\n");
      previous_ms = timing.update_ms;
      previous_count = count;
    }
  }
  return 0;
}
