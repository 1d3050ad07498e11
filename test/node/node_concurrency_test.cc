// Acceptance 9: four client threads spawn, query and delete 200 models each
// while the world steps as fast as it can. Every answer must be the one the
// call sequence implies.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
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

// A chain of `links` links hinged to the world and to each other about y,
// joints j0, j1, ...: each link a 1 kg ball of radius 0.05 m, 0.2 m below
// its hinge.
std::string ChainUrdf(int links) {
  std::string urdf = R"(<robot name="chain"><link name="world"/>)";
  std::string parent = "world";
  for (int k = 0; k < links; ++k) {
    const std::string link = "l" + std::to_string(k);
    urdf += "<joint name=\"j" + std::to_string(k) + "\" type=\"continuous\"><parent link=\"" +
            parent + "\"/><child link=\"" + link + "\"/><origin xyz=\"0 0 " +
            (k == 0 ? "3" : "-0.2") + "\"/><axis xyz=\"0 1 0\"/></joint>";
    urdf += "<link name=\"" + link + R"("><inertial><origin xyz="0 0 -0.2"/><mass value="1"/>)" +
            R"(<inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial>)" +
            R"(<collision><origin xyz="0 0 -0.2"/><geometry><sphere radius="0.05"/></geometry>)" +
            "</collision></link>";
    parent = link;
  }
  return urdf + "</robot>";
}

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
// the node. Each cycle spawns the model, waits until its command
// subscriber is connected to the test's flooding publisher, and deletes it
// with commands still queued, so a callback is often waiting for the world
// when the delete takes it.
TEST(ConcurrencyTest, DeletingAModelWhileItsJointCommandsArriveNeverHangs) {
  constexpr int kCycles = 60;
  constexpr int kLinks = 30;
  constexpr double kTimeout = 240.0;  // s of wall time for all cycles
  SimClient setup;
  ASSERT_TRUE(setup.WaitForServices(20.0));
  ASSERT_TRUE(setup.SetPaused(false));
  struct Progress {
    ros::Publisher command;
    std::atomic<int> cycles_done{0};
    std::mutex mutex;
    std::vector<std::string> failures;  // guarded by mutex
  };
  // Shared with a detached thread: a hung node leaves it blocked in a
  // service call for good.
  const auto progress = std::make_shared<Progress>();
  ros::NodeHandle node("/rigid_body_sim");
  progress->command = node.advertise<sensor_msgs::JointState>("busy_chain/joint_command", 1);
  std::atomic<bool> stop{false};
  std::thread commander([&] {
    sensor_msgs::JointState message;
    message.name = {"j0"};
    message.effort = {0.5};
    while (!stop.load()) {
      progress->command.publish(message);
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
  });
  std::thread([progress] {
    SimClient client(/*persistent=*/true);
    const std::string urdf = ChainUrdf(kLinks);
    const auto subscribers = [&progress](bool connected) {
      return WaitFor([&] { return (progress->command.getNumSubscribers() > 0) == connected; },
                     10.0);
    };
    for (int i = 0; i < kCycles; ++i) {
      const auto spawned = client.SpawnUrdf("busy_chain", urdf, MakePose(0, 0, 0));
      const bool connected = subscribers(true);
      std::this_thread::sleep_for(std::chrono::milliseconds(i % 7 * 3));
      const auto deleted = client.Delete("busy_chain");
      const bool disconnected = subscribers(false);
      // Reported by the test's thread: this one may outlive the test.
      if (!spawned.success || !connected || !deleted.success || !disconnected) {
        const std::lock_guard<std::mutex> lock(progress->mutex);
        progress->failures.push_back("cycle " + std::to_string(i) + ": spawn '" + spawned.message +
                                     "', connected " + std::to_string(connected) + ", delete '" +
                                     deleted.message + "', disconnected " +
                                     std::to_string(disconnected));
      }
      ++progress->cycles_done;
    }
  }).detach();
  const bool finished = WaitFor([&] { return progress->cycles_done.load() == kCycles; }, kTimeout);
  stop = true;
  commander.join();
  EXPECT_TRUE(finished) << "the node stopped answering after " << progress->cycles_done.load()
                        << " of " << kCycles << " spawn and delete cycles";
  const std::lock_guard<std::mutex> lock(progress->mutex);
  for (const std::string& failure : progress->failures) ADD_FAILURE() << failure;
}

}  // namespace
}  // namespace rigid_body_sim::test
