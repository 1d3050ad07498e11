// Acceptance 9: four client threads spawn, query and delete 200 models each
// while the world steps as fast as it can. Every answer must be the one the
// call sequence implies.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "sim_client.h"

namespace rigid_body_sim::test {
namespace {

constexpr int kThreads = 4;
constexpr int kIterations = 200;
constexpr double kSpawnHeight = 20.0;  // m

TEST(ConcurrencyTest, ParallelSpawnGetStateDeleteGiveConsistentAnswers) {
  SimClient setup;
  ASSERT_TRUE(setup.WaitForServices(20.0));
  ASSERT_TRUE(setup.SetPaused(false));
  ros::NodeHandle node("/rigid_body_sim");
  Latest<rigid_body_sim::ModelStates> states(node, "states");
  const std::string urdf = BoxUrdf(0.3, 0.3, 0.3, 1.0);
  std::atomic<int> failures{0};
  const auto worker = [&](int thread) {
    SimClient client(/*persistent=*/true);
    for (int i = 0; i < kIterations; ++i) {
      const std::string name = "t" + std::to_string(thread) + "_" + std::to_string(i);
      const double x = 2.0 * thread;
      const double y = 0.5 * (i % 10);
      const auto spawned = client.SpawnUrdf(name, urdf, MakePose(x, y, kSpawnHeight));
      const auto state = client.GetState(name);
      // Falling from rest: below the spawn height, above where 1 s of free
      // fall ends for the slowest plausible run, never sideways.
      const bool state_ok = state.success && std::isfinite(state.pose.position.z) &&
                            state.pose.position.z <= kSpawnHeight &&
                            std::abs(state.pose.position.x - x) < 1e-6 &&
                            std::abs(state.pose.position.y - y) < 1e-6;
      const auto deleted = client.Delete(name);
      const auto gone = client.GetState(name);
      const bool ok = spawned.success && spawned.frames.size() == 1 &&
                      spawned.frames[0] == name + "/base_link" && state_ok && deleted.success &&
                      !gone.success;
      if (!ok) {
        ++failures;
        ADD_FAILURE() << name << ": spawn '" << spawned.message << "', get_state " << state.success
                      << " z " << state.pose.position.z << " '" << state.message << "', delete '"
                      << deleted.message << "', get_state after delete " << gone.success;
      }
    }
  };
  std::vector<std::thread> threads;
  for (int thread = 0; thread < kThreads; ++thread) threads.emplace_back(worker, thread);
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(failures.load(), 0);
  // Every model is gone, and the world kept stepping.
  const auto before = states.Next(20.0);
  ASSERT_TRUE(before.has_value());
  EXPECT_TRUE(before->name.empty());
  const auto after = states.Next(20.0);
  ASSERT_TRUE(after.has_value());
  EXPECT_GT(after->header.stamp, before->header.stamp);
}

}  // namespace
}  // namespace rigid_body_sim::test
