// Threads in a step (WorldSettings::threads): the task pool itself, and a
// world stepped on two threads against the single-thread reference. The
// narrow phase tests each shape pair alone and the resting solve sweeps each
// island exactly as one thread would, so the results must be equal bit for
// bit, for every thread count and every run.
#include <algorithm>
#include <atomic>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <vector>

#include <gtest/gtest.h>

#include "physics/world/task_pool.h"
#include "rigid_body_sim/physics/world.h"
#include "scene.h"
#include "state_hash.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::AddGround;
using testing::AddSphere;
using testing::BoxSpec;
using testing::MakeMaterial;
using testing::SphereSpec;
using testing::StateHash;

TEST(TaskPoolTest, ParallelForVisitsEveryIndexOnce) {
  for (const int threads : {1, 2, 3}) {
    TaskPool pool(threads);
    EXPECT_EQ(pool.threads(), threads);
    for (const std::size_t count : {0u, 1u, 31u, 32u, 33u, 1000u, 4099u}) {
      std::vector<std::atomic<int>> visits(count);
      pool.ParallelFor(count, 32, [&](std::size_t i) { visits[i].fetch_add(1); });
      for (std::size_t i = 0; i < count; ++i) {
        ASSERT_EQ(visits[i].load(), 1) << "threads " << threads << " count " << count << " i " << i;
      }
    }
  }
}

TEST(TaskPoolTest, RunOnAllCallsEachThreadIndexOnceAndWaits) {
  TaskPool pool(3);
  for (int round = 0; round < 200; ++round) {
    std::vector<std::atomic<int>> calls(3);
    pool.RunOnAll([&](int thread) { calls[static_cast<std::size_t>(thread)].fetch_add(1); });
    // RunOnAll has returned, so every call has.
    for (int thread = 0; thread < 3; ++thread) ASSERT_EQ(calls[thread].load(), 1);
  }
}

TEST(ThreadsTest, SettingIsValidatedWithItsRange) {
  WorldSettings settings;
  for (const int threads : {0, 1, 2, kMaxThreads}) {
    settings.threads = threads;
    EXPECT_TRUE(ValidateWorldSettings(settings).ok()) << threads;
  }
  for (const int threads : {-1, kMaxThreads + 1}) {
    settings.threads = threads;
    const Status status = ValidateWorldSettings(settings);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message().find("threads " + std::to_string(threads)), std::string::npos)
        << status.message();
    EXPECT_NE(status.message().find("[0, 256]"), std::string::npos) << status.message();
  }
  World world;
  settings.threads = -1;
  EXPECT_FALSE(world.SetSettings(settings).ok());
  EXPECT_EQ(world.settings().threads, 1);
  settings.threads = 2;
  EXPECT_TRUE(world.SetSettings(settings).ok());
  EXPECT_EQ(world.settings().threads, 2);
}

constexpr int kPiles = 4;
constexpr int kBoxesPerPile = 75;  // 3 x 5 columns, 5 high

// Four piles of 75 boxes of 10 cm, 2 m apart so that each is an island of
// its own once landed: columns 13 cm apart, each box tilted and off its
// column by a few millimetres, dropped from up to 0.7 m so that they hit,
// topple and settle into heaps. A few spheres per pile bounce among them.
std::vector<BodyId> BuildPiles(World* world) {
  std::vector<BodyId> bodies;
  AddGround(world, MakeMaterial(0.6, 0.0));
  for (int pile = 0; pile < kPiles; ++pile) {
    const double cx = 2.0 * (pile % 2) - 1.0;
    const double cy = 2.0 * (pile / 2) - 1.0;
    for (int n = 0; n < kBoxesPerPile; ++n) {
      const int k = pile * kBoxesPerPile + n;
      const int column = n % 15;
      const int layer = n / 15;
      const Pose pose{
          Vec3(cx + 0.13 * (column % 3 - 1) + 0.004 * std::sin(1.3 * k),
               cy + 0.13 * (column / 3 - 2) + 0.004 * std::cos(1.7 * k), 0.08 + 0.14 * layer),
          Quat(Eigen::AngleAxisd(0.2 * std::sin(0.7 * k),
                                 Vec3(std::cos(k), std::sin(k), 0.4).normalized()))};
      if (n % 25 == 24) {
        SphereSpec spec;
        spec.radius = 0.05;
        spec.mass = 0.5;
        spec.world_from_body = pose;
        spec.material = MakeMaterial(0.5, 0.4);
        bodies.push_back(AddSphere(world, spec));
        continue;
      }
      BoxSpec spec;
      spec.size = Vec3(0.1, 0.1, 0.1);
      spec.mass = 1.0 + 0.25 * (k % 3);
      spec.world_from_body = pose;
      spec.angular_velocity = Vec3(0.3 * std::sin(k), 0.3 * std::cos(k), 0.0);
      spec.material = MakeMaterial(0.5, 0.0);
      bodies.push_back(AddBox(world, spec));
    }
  }
  return bodies;
}

std::uint64_t HashBodies(const World& world, const std::vector<BodyId>& bodies) {
  StateHash hash;
  for (const BodyId body : bodies) {
    const Pose pose = world.GetPose(body);
    hash.Add(pose.translation);
    hash.Add(pose.rotation);
    hash.Add(world.GetLinearVelocity(body));
    hash.Add(world.GetAngularVelocity(body));
  }
  hash.Add(world.time());
  return hash.value();
}

// The contact reports of the last step, bit for bit, in their order.
std::uint64_t HashContacts(const World& world) {
  StateHash hash;
  for (const ContactReport& report : world.contacts()) {
    hash.Add(static_cast<double>(report.body_a.index));
    hash.Add(static_cast<double>(report.body_b.index));
    hash.Add(report.position_world);
    hash.Add(report.normal_world);
    hash.Add(report.normal_impulse);
    hash.Add(report.friction_impulse_world);
  }
  return hash.value();
}

WorldSettings WithThreads(int threads, MotionSolverKind solver = MotionSolverKind::kExact) {
  WorldSettings settings;
  settings.threads = threads;
  settings.motion_solver = solver;
  return settings;
}

struct PileRun {
  std::uint64_t hash = 0;  // after kSteps steps
  int most_island_groups = 0;
  std::size_t most_solver_points = 0;
  double top = 0.0;  // m, the highest body's height at the end
};

constexpr int kSteps = 1000;

PileRun RunPiles(int threads, MotionSolverKind solver = MotionSolverKind::kExact) {
  World world(WithThreads(threads, solver));
  const std::vector<BodyId> bodies = BuildPiles(&world);
  PileRun run;
  for (int step = 0; step < kSteps; ++step) {
    world.Step();
    run.most_island_groups =
        std::max(run.most_island_groups, world.last_step_profile().island_groups);
    run.most_solver_points =
        std::max(run.most_solver_points, world.last_step_profile().solver_points);
  }
  double top = 0.0;
  for (const BodyId body : bodies) top = std::max(top, world.GetPose(body).translation.z());
  run.top = top;
  run.hash = HashBodies(world, bodies);
  std::printf("%d thread(s): hash %016" PRIx64
              ", at most %d island groups, at most %zu contact points, top at %.3f m\n",
              threads, run.hash, run.most_island_groups, run.most_solver_points, top);
  return run;
}

// 1,000 steps of 300 bodies, twice on one thread and twice on two: the same
// hash every time.
TEST(ThreadsTest, PileHashIsTheSameForEveryRunAndThreadCount) {
  const PileRun one = RunPiles(1);
  const PileRun one_again = RunPiles(1);
  const PileRun two = RunPiles(2);
  const PileRun two_again = RunPiles(2);
  // Not trivial: the columns came down (the top box from 0.64 m to below
  // 0.5 m), many points were solved at once, and on two threads the islands
  // were shared.
  EXPECT_LT(one.top, 0.5);
  EXPECT_GT(one.most_solver_points, 400u);
  EXPECT_EQ(one.most_island_groups, 1);
  EXPECT_EQ(two.most_island_groups, 2);

  EXPECT_EQ(one_again.hash, one.hash);
  EXPECT_EQ(two_again.hash, two.hash);
  EXPECT_EQ(two.hash, one.hash);
}

// The soft step's colours on two threads: the same hash as on one, run
// after run (the colours share no moving body, so the split of a colour
// among threads cannot change a bit).
TEST(ThreadsTest, SoftStepPileHashIsTheSameForEveryRunAndThreadCount) {
  const PileRun one = RunPiles(1, MotionSolverKind::kSoftStep);
  const PileRun one_again = RunPiles(1, MotionSolverKind::kSoftStep);
  const PileRun two = RunPiles(2, MotionSolverKind::kSoftStep);
  EXPECT_LT(one.top, 0.5);
  EXPECT_GT(one.most_solver_points, 400u);
  EXPECT_EQ(one_again.hash, one.hash);
  EXPECT_EQ(two.hash, one.hash);
}

// Step by step, every body's state and every contact report of a world on
// two threads equal the single-thread reference's, for either solver.
void ExpectTwoThreadsStepLikeTheReference(MotionSolverKind solver) {
  World reference(WithThreads(1, solver));
  World threaded(WithThreads(2, solver));
  const std::vector<BodyId> reference_bodies = BuildPiles(&reference);
  const std::vector<BodyId> threaded_bodies = BuildPiles(&threaded);
  std::size_t most_reports = 0;
  for (int step = 0; step < 400; ++step) {
    reference.Step();
    threaded.Step();
    ASSERT_EQ(HashBodies(threaded, threaded_bodies), HashBodies(reference, reference_bodies))
        << "step " << step;
    ASSERT_EQ(threaded.contacts().size(), reference.contacts().size()) << "step " << step;
    ASSERT_EQ(HashContacts(threaded), HashContacts(reference)) << "step " << step;
    most_reports = std::max(most_reports, reference.contacts().size());
  }
  EXPECT_GT(most_reports, 400u);
}

TEST(ThreadsTest, TwoThreadsStepLikeTheReferenceEveryStep) {
  ExpectTwoThreadsStepLikeTheReference(MotionSolverKind::kExact);
}

TEST(ThreadsTest, SoftStepTwoThreadsStepLikeTheReferenceEveryStep) {
  ExpectTwoThreadsStepLikeTheReference(MotionSolverKind::kSoftStep);
}

// A pyramid of `rows` unit boxes spawned touching, each box on two: every
// box in contact with up to six, its supports all new at the first step.
std::vector<BodyId> BuildPyramid(World* world, int rows) {
  std::vector<BodyId> bodies;
  AddGround(world, MakeMaterial(0.6, 0.0));
  for (int row = 0; row < rows; ++row) {
    for (int i = 0; i < rows - row; ++i) {
      BoxSpec spec;
      spec.material = MakeMaterial(0.6, 0.0);
      spec.world_from_body =
          Pose{Vec3(i - 0.5 * (rows - row - 1), 0.0, 0.5 + row), Quat::Identity()};
      bodies.push_back(AddBox(world, spec));
    }
  }
  return bodies;
}

// Step by step, the soft step with its contacts four at a time in SIMD
// lanes (SoftStepSettings::simd_lanes) gives every body's state and every
// contact report of the scalar update, bit for bit; both step compact from
// `compact_blocks_from` blocks on (-1: the default).
void ExpectLanesStepLikeTheScalarUpdate(const std::function<std::vector<BodyId>(World*)>& build,
                                        int threads, int steps, int compact_blocks_from = -1) {
  WorldSettings lane_settings = WithThreads(threads, MotionSolverKind::kSoftStep);
  if (compact_blocks_from >= 0) lane_settings.soft_step.compact_blocks_from = compact_blocks_from;
  WorldSettings scalar_settings = lane_settings;
  scalar_settings.soft_step.simd_lanes = false;
  World scalar(scalar_settings);
  World lanes(lane_settings);
  ASSERT_TRUE(lanes.settings().soft_step.simd_lanes);
  const std::vector<BodyId> scalar_bodies = build(&scalar);
  const std::vector<BodyId> lane_bodies = build(&lanes);
  std::size_t most_reports = 0;
  for (int step = 0; step < steps; ++step) {
    scalar.Step();
    lanes.Step();
    ASSERT_EQ(HashBodies(lanes, lane_bodies), HashBodies(scalar, scalar_bodies)) << "step " << step;
    ASSERT_EQ(HashContacts(lanes), HashContacts(scalar)) << "step " << step;
    most_reports = std::max(most_reports, scalar.contacts().size());
  }
  EXPECT_GT(most_reports, 40u);
}

TEST(ThreadsTest, SoftStepLanesStepLikeTheScalarUpdateOnPiles) {
  ExpectLanesStepLikeTheScalarUpdate(BuildPiles, 1, 400);
  ExpectLanesStepLikeTheScalarUpdate(BuildPiles, 2, 200);
}

TEST(ThreadsTest, SoftStepLanesStepLikeTheScalarUpdateOnAPyramid) {
  ExpectLanesStepLikeTheScalarUpdate([](World* world) { return BuildPyramid(world, 12); }, 1, 240);
}

// Compact blocks (floats for what the sub-steps only read) from the first
// block on, and from 12 blocks on, which the falling piles cross as their
// contacts grow: each layout, and the switch between them, gives the
// scalar update's bits.
TEST(ThreadsTest, SoftStepCompactLanesStepLikeTheScalarUpdate) {
  ExpectLanesStepLikeTheScalarUpdate(BuildPiles, 1, 400, /*compact_blocks_from=*/0);
  ExpectLanesStepLikeTheScalarUpdate(BuildPiles, 2, 200, /*compact_blocks_from=*/0);
  ExpectLanesStepLikeTheScalarUpdate(BuildPiles, 2, 400, /*compact_blocks_from=*/12);
  ExpectLanesStepLikeTheScalarUpdate([](World* world) { return BuildPyramid(world, 12); }, 1, 240,
                                     /*compact_blocks_from=*/0);
}

}  // namespace
}  // namespace rigid_body_sim::physics
