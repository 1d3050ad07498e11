// Times the soft step's lane updates (solver/soft_contact_lanes.h) per block
// of four 4-point contacts, for working sets from a few hundred kilobytes to
// beyond the last-level cache: each sub-step's passes stream every block, so
// the time per block grows once the blocks outgrow the cache. The block
// counts bracket the benchmark's scenes (pyramid_40 about 600 blocks,
// pyramid_90 about 3,000, pile_4000's awake steps up to 6,000).
//
// Each block's lanes join random pairs of twice as many bodies as blocks
// (moving, unit mass and inertia), resting 1 mm deep on their normal, so
// that the solve's every branch runs and the velocities stay finite. The
// passes alternate solve and relax, as the sub-steps do. Each count is timed
// with wide blocks (doubles) and compact ones (what the passes only read in
// floats: SoftStepSettings::compact_blocks_from picks between them).
//
// Usage: soft_lanes_bench [passes over 1,000 blocks]   (default 400)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <random>
#include <vector>

#include "physics/solver/soft_contact_lanes.h"

namespace rigid_body_sim::physics {
namespace {

SoftConstraint RestingContact(std::uint32_t body_a, std::uint32_t body_b) {
  SoftConstraint c{};
  c.body_a = body_a;
  c.body_b = body_b;
  c.normal = Vec3::UnitZ();
  c.tangent = {Vec3::UnitX(), Vec3::UnitY()};
  // Friction at the centroids, anchored there (unit inverse inertia).
  c.centre_a = Vec3(0.0, 0.0, -0.1);
  c.centre_b = Vec3(0.0, 0.0, 0.1);
  c.anchor_a = c.centre_a;
  c.anchor_b = c.centre_b;
  for (int k = 0; k < 2; ++k) {
    c.ct_a[k] = c.centre_a.cross(c.tangent[k]);
    c.ct_b[k] = c.centre_b.cross(c.tangent[k]);
    c.ang_t_a[k] = c.ct_a[k];
    c.ang_t_b[k] = c.ct_b[k];
    c.anchor_t_a[k] = c.ct_a[k];
    c.anchor_t_b[k] = c.ct_b[k];
  }
  c.twist_a = c.normal;
  c.twist_b = c.normal;
  c.inverse_mass_a = 1.0;
  c.inverse_mass_b = 1.0;
  c.friction = 0.5;
  c.bias_rate = 10.0;
  c.mass_scale = 0.9;
  c.impulse_scale = 0.1;
  c.tangent_block = {0.5, 0.0, 0.5};
  c.twist_mass = 0.1;
  c.twist_arm = 0.1;
  c.point_count = ContactManifold::kMaxPoints;
  const double corner[4][2] = {{0.1, 0.1}, {-0.1, 0.1}, {-0.1, -0.1}, {0.1, -0.1}};
  for (int i = 0; i < c.point_count; ++i) {
    SoftPoint& p = c.points[i];
    p.rn_a = Vec3(corner[i][0], corner[i][1], -0.1).cross(c.normal);
    p.rn_b = Vec3(corner[i][0], corner[i][1], 0.1).cross(c.normal);
    p.ang_a = p.rn_a;  // unit inverse inertia
    p.ang_b = p.rn_b;
    p.normal_mass = 1.0 / (2.0 + p.rn_a.squaredNorm() + p.rn_b.squaredNorm());
    p.start_separation = -0.001;
  }
  return c;
}

struct Timing {
  double warm_start_ns;  // per block and pass
  double solve_ns;
};

template <typename Block>
Timing TimeBlocks(int block_count, int passes) {
  const std::uint32_t bodies = 2 * static_cast<std::uint32_t>(block_count);
  std::vector<SoftRowState> states(
      bodies, SoftRowState{Vec3(0.0, 0.0, -0.01), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()});
  const std::vector<std::uint8_t> moving(bodies, 1);
  std::vector<Block> blocks(block_count);
  std::mt19937 random(7);
  for (int b = 0; b < block_count; ++b) {
    SoftConstraint lanes[kBatchLanes];
    for (SoftConstraint& lane : lanes) {
      const std::uint32_t a = random() % bodies;
      lane = RestingContact(a, (a + 1 + random() % (bodies - 1)) % bodies);
    }
    PackSoftBlock(lanes, static_cast<std::uint32_t>(kBatchLanes * b), kBatchLanes, moving,
                  &blocks[b]);
  }
  SoftLaneContext context;
  context.states = &states;
  context.h = 1.0 / 960.0;
  context.max_push_velocity = 3.0;
  context.collision_velocity_threshold = 0.5;
  Block* const begin = blocks.data();
  Block* const end = begin + block_count;
  // Processor time, not wall time, so that other load does not count.
  const std::clock_t start = std::clock();
  for (int pass = 0; pass < passes; ++pass) WarmStartSoftBlocks(context, begin, end);
  const std::clock_t middle = std::clock();
  for (int pass = 0; pass < passes; ++pass) SolveSoftBlocks(context, pass % 2 == 0, begin, end);
  const std::clock_t stop = std::clock();
  const double per_block = 1e9 / CLOCKS_PER_SEC / passes / block_count;
  return {per_block * static_cast<double>(middle - start),
          per_block * static_cast<double>(stop - middle)};
}

int Main(int argc, char** argv) {
  const int work = argc > 1 ? std::max(1, std::atoi(argv[1])) : 400;
  std::printf(
      "soft step lane updates per block of %d contacts: wide blocks %zu bytes, compact %zu\n",
      kBatchLanes, sizeof(SoftLaneBlock), sizeof(CompactSoftLaneBlock));
  std::printf("%8s %10s %12s %12s %12s %12s\n", "blocks", "wide MB", "wide warm", "wide solve",
              "compact warm", "compact solve");
  for (const int block_count : {100, 600, 1500, 2000, 3000, 6000}) {
    const int passes = std::max(2, work * 1000 / block_count);
    const Timing wide = TimeBlocks<SoftLaneBlock>(block_count, passes);
    const Timing compact = TimeBlocks<CompactSoftLaneBlock>(block_count, passes);
    std::printf("%8d %10.1f %12.1f %12.1f %12.1f %12.1f\n", block_count,
                1e-6 * block_count * sizeof(SoftLaneBlock), wide.warm_start_ns, wide.solve_ns,
                compact.warm_start_ns, compact.solve_ns);
  }
  return 0;
}

}  // namespace
}  // namespace rigid_body_sim::physics

int main(int argc, char** argv) { return rigid_body_sim::physics::Main(argc, argv); }
