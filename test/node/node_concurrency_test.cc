// Acceptance 9: four client threads spawn, query and delete 200 models each
// while the world steps as fast as it can. Every answer must be the one the
// call sequence implies.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <sensor_msgs/JointState.h>

#include "sim_client.h"

namespace rigid_body_sim::test {
namespace {

constexpr int kThreads = 4;
constexpr int kIterations = 200;
constexpr double kSpawnHeight = 20.0;  // m

// A pendulum hinged to the world: a 1 kg ball on a massless 1 m rod.
constexpr char kPendulumUrdf[] = R"(<robot name="pendulum">
  <link name="world"/>
  <joint name="mount" type="fixed"><parent link="world"/><child link="pivot"/></joint>
  <link name="pivot"><inertial><mass value="0.1"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="continuous"><parent link="pivot"/><child link="bob"/>
    <axis xyz="0 1 0"/></joint>
  <link name="bob"><inertial><origin xyz="0 0 -1"/><mass value="1"/>
    <inertia ixx="4e-5" iyy="4e-5" izz="4e-5" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 -1"/><geometry><sphere radius="0.01"/></geometry></collision>
  </link>
</robot>)";

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

// A model deleted while joint commands stream in: roscpp's unsubscribe
// waits for a running callback, and the node's command callback waits for
// the world, so destroying the subscriber under the world's lock would hang
// the node. Commands come from a latched publisher, so each new subscriber
// gets one at once, and the world steps as fast as it can, so a callback is
// often waiting for the lock when the delete takes it.
TEST(ConcurrencyTest, DeletingAModelWhileItsJointCommandsArriveNeverHangs) {
  constexpr int kCycles = 60;
  constexpr double kTimeout = 240.0;  // s of wall time for all cycles
  SimClient setup;
  ASSERT_TRUE(setup.WaitForServices(20.0));
  ASSERT_TRUE(setup.SetPaused(false));
  ros::NodeHandle node("/rigid_body_sim");
  ros::Publisher command =
      node.advertise<sensor_msgs::JointState>("busy_pendulum/joint_command", 1, /*latch=*/true);
  std::atomic<bool> stop{false};
  std::thread commander([&] {
    sensor_msgs::JointState message;
    message.name = {"hinge"};
    message.effort = {0.5};
    while (!stop.load()) {
      command.publish(message);
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  });
  struct Progress {
    std::atomic<int> cycles_done{0};
    std::atomic<int> failures{0};
  };
  const auto progress = std::make_shared<Progress>();
  // Detached, holding its own share of the progress: a hung node leaves it
  // blocked in a service call for good.
  std::thread([progress] {
    SimClient client(/*persistent=*/true);
    for (int i = 0; i < kCycles; ++i) {
      const auto spawned = client.SpawnUrdf("busy_pendulum", kPendulumUrdf, MakePose(0, 0, 3));
      std::this_thread::sleep_for(std::chrono::milliseconds(20 + i % 7 * 5));
      const auto deleted = client.Delete("busy_pendulum");
      if (!spawned.success || !deleted.success) ++progress->failures;
      ++progress->cycles_done;
    }
  }).detach();
  const bool finished =
      WaitFor([&] { return progress->cycles_done.load() == kCycles; }, kTimeout);
  stop = true;
  commander.join();
  ASSERT_TRUE(finished) << "the node stopped answering after " << progress->cycles_done.load()
                        << " of " << kCycles << " spawn and delete cycles";
  EXPECT_EQ(progress->failures.load(), 0);
}

}  // namespace
}  // namespace rigid_body_sim::test
