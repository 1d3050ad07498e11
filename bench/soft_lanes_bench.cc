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

// Constraints into blocks, lane by lane (the soft step prepares its blocks
// in their lanes, soft_contact_prepare.cc; this benchmark packs constraints
// it makes itself).
// Lane `lane` of the lanes set from x (of the 3-vectors lanes[axis] from
// v). Into floats only in a compact step, whose rows hold floats' values
// (NarrowToFloat), so exactly.
void SetLane(double x, int lane, LaneFloats* lanes) { (*lanes)[lane] = static_cast<float>(x); }
void SetLane(double x, int lane, LaneDoubles* lanes) { (*lanes)[lane] = x; }

void SetLane(const Vec3& v, int lane, LaneFloats (&lanes)[3]) {
  for (int axis = 0; axis < 3; ++axis) SetLane(v[axis], lane, &lanes[axis]);
}
void SetLane(const Vec3& v, int lane, LaneDoubles (&lanes)[3]) {
  for (int axis = 0; axis < 3; ++axis) SetLane(v[axis], lane, &lanes[axis]);
}

template <typename LanePoint>
void PackPoint(const SoftPoint& from, int lane, LanePoint* to, LaneMask* carried) {
  SetLane(from.rn_a, lane, to->rn_a);
  SetLane(from.rn_b, lane, to->rn_b);
  SetLane(from.ang_a, lane, to->ang_a);
  SetLane(from.ang_b, lane, to->ang_b);
  SetLane(from.start_separation, lane, &to->start_separation);
  SetLane(from.preload, lane, &to->preload);
  to->normal_mass[lane] = from.normal_mass;
  to->normal_impulse[lane] = from.normal_impulse;
  to->max_normal_impulse[lane] = from.max_normal_impulse;
  to->total_normal_impulse[lane] = from.total_normal_impulse;
  to->approach_velocity[lane] = from.approach_velocity;
  to->closed[lane] = from.closed ? -1 : 0;
  (*carried)[lane] = from.carried ? -1 : 0;
}

template <typename Block>
void PackFriction(const SoftConstraint& c, int lane, Block* block) {
  for (int k = 0; k < 2; ++k) {
    SetLane(c.tangent[k], lane, block->tangent[k]);
    SetLane(c.ang_t_a[k], lane, block->ang_t_a[k]);
    SetLane(c.ang_t_b[k], lane, block->ang_t_b[k]);
    SetLane(c.slip_start[k], lane, &block->slip_start[k]);
    block->tangent_impulse[k][lane] = c.tangent_impulse[k];
    block->total_tangent_impulse[k][lane] = c.total_tangent_impulse[k];
  }
  SetLane(c.centre_a, lane, block->centre_a);
  SetLane(c.centre_b, lane, block->centre_b);
  SetLane(c.twist_a, lane, block->twist_a);
  SetLane(c.twist_b, lane, block->twist_b);
  for (int k = 0; k < 3; ++k) block->tangent_block[k][lane] = c.tangent_block[k];
  block->twist_mass[lane] = c.twist_mass;
  SetLane(c.twist_arm, lane, &block->twist_arm);
  block->twist_impulse[lane] = c.twist_impulse;
}

template <typename Block>
void PackSoftBlock(const SoftConstraint* constraints, std::uint32_t first, int lanes,
                   const std::vector<std::uint8_t>& moving, Block* block) {
  block->lanes = lanes;
  block->max_points = 0;
  for (int lane = 0; lane < kBatchLanes; ++lane) {
    block->point_count[lane] = lane < lanes ? constraints[lane].point_count : 0;
  }
  for (int lane = 0; lane < kBatchLanes; ++lane) {
    // A lane without a constraint reads the first lane's bodies, and is
    // neither written back nor stored.
    const int from = lane < lanes ? lane : 0;
    const SoftConstraint& c = constraints[from];
    block->constraint[lane] = first + static_cast<std::uint32_t>(from);
    block->body_a[lane] = c.body_a;
    block->body_b[lane] = c.body_b;
    block->moves_a[lane] = lane < lanes && moving[c.body_a] != 0;
    block->moves_b[lane] = lane < lanes && moving[c.body_b] != 0;
    if (lane >= lanes) continue;
    block->max_points = std::max(block->max_points, c.point_count);
    SetLane(c.normal, lane, block->normal);
    block->inverse_mass_a[lane] = c.inverse_mass_a;
    block->inverse_mass_b[lane] = c.inverse_mass_b;
    SetLane(c.friction, lane, &block->friction);
    SetLane(c.restitution, lane, &block->restitution);
    SetLane(c.bias_rate, lane, &block->bias_rate);
    SetLane(c.mass_scale, lane, &block->mass_scale);
    SetLane(c.impulse_scale, lane, &block->impulse_scale);
    SetLane(c.anchor_a, lane, block->anchor_a);
    SetLane(c.anchor_b, lane, block->anchor_b);
    PackFriction(c, lane, block);
    for (int i = 0; i < c.point_count; ++i) {
      PackPoint(c.points[i], lane, &block->points[i], &block->carried[i]);
    }
  }
}

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
