// Hostile messages on the joint topics and hostile URIs, through the node's
// ROS interface: a trajectory stamped 2^32 s away, one past
// ~max_trajectory_points, a joint_command of a million names, and a
// package:// URI that climbs out of its package. The node must stay alive,
// refuse them whole, follow the next good message, and answer other calls
// within 0.5 s while a long trajectory within the limits is taken in.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <sensor_msgs/JointState.h>
#include <trajectory_msgs/JointTrajectory.h>

#include "sim_client.h"

namespace rigid_body_sim::test {
namespace {

constexpr double kTimeout = 20.0;  // s of wall time for any single wait
constexpr char kArmUri[] = "package://rigid_body_sim/test/data/two_link_arm.urdf";

// The shoulder's angle from the upper arm's orientation: a turn about y.
double ShoulderAngle(SimClient& client) {
  const auto state = client.GetState("arm/upper_arm");
  if (!state.success) return std::numeric_limits<double>::quiet_NaN();
  return 2.0 * std::atan2(state.pose.orientation.y, state.pose.orientation.w);
}

trajectory_msgs::JointTrajectory Trajectory(int points, double shoulder, double duration) {
  trajectory_msgs::JointTrajectory message;
  message.joint_names = {"shoulder", "elbow"};
  message.points.resize(static_cast<std::size_t>(points));
  for (int i = 0; i < points; ++i) {
    message.points[i].positions = {shoulder, 0.0};
    message.points[i].time_from_start = ros::Duration(duration * (i + 1) / points);
  }
  return message;
}

class NodeHostileJointsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(client_.WaitForServices(kTimeout));
    ASSERT_TRUE(client_.SetPaused(false));
    rigid_body_sim::Spawn::Request request;
    request.name = "arm";
    request.urdf_path = kArmUri;
    // Its base 1.5 m up, the arm (1 m) hanging clear of the ground.
    request.pose = MakePose(0, 0, 1.5);
    request.friction = -1.0;
    request.restitution = -1.0;
    const auto spawned = client_.Spawn(request);
    ASSERT_TRUE(spawned.success) << spawned.message;
    trajectory_ = node_.advertise<trajectory_msgs::JointTrajectory>(
        "/rigid_body_sim/arm/joint_trajectory", 2);
    command_ = node_.advertise<sensor_msgs::JointState>("/rigid_body_sim/arm/joint_command", 2);
    ASSERT_TRUE(WaitFor(
        [&] { return trajectory_.getNumSubscribers() > 0 && command_.getNumSubscribers() > 0; },
        kTimeout));
  }
  void TearDown() override { client_.Delete("arm"); }

  // A good trajectory sent after the hostile message on the same topic
  // (so it is taken after it) moves the shoulder to `angle`: the node
  // lived through the hostile one and still follows its joint topics.
  void ExpectFollowsNext(double angle) {
    trajectory_.publish(Trajectory(2, angle, 0.2));
    EXPECT_TRUE(WaitFor([&] { return std::abs(ShoulderAngle(client_) - angle) < 1e-3; }, kTimeout))
        << "shoulder at " << ShoulderAngle(client_) << " rad, not " << angle;
  }

  ros::NodeHandle node_;
  SimClient client_{/*persistent=*/true};
  ros::Publisher trajectory_;
  ros::Publisher command_;
};

TEST_F(NodeHostileJointsTest, StampFarFromTheClockIsRefusedNotFatal) {
  trajectory_msgs::JointTrajectory message = Trajectory(1, 1.0, 0.2);
  message.header.stamp.sec = std::numeric_limits<std::uint32_t>::max();
  message.header.stamp.nsec = 999999999;
  trajectory_.publish(message);
  ExpectFollowsNext(0.4);
  // A stamp 1 s old is within the rule: the trajectory has run for 1 s
  // when it arrives, past its 0.2 s, so its last point holds at once.
  ASSERT_TRUE(WaitFor([] { return ros::Time::now().toSec() > 1.5; }, kTimeout));
  trajectory_msgs::JointTrajectory late = Trajectory(1, -0.3, 0.2);
  late.header.stamp = ros::Time::now() - ros::Duration(1.0);
  trajectory_.publish(late);
  EXPECT_TRUE(WaitFor([&] { return std::abs(ShoulderAngle(client_) + 0.3) < 1e-3; }, kTimeout));
}

TEST_F(NodeHostileJointsTest, TrajectoryPastThePointLimitIsRefused) {
  ExpectFollowsNext(0.2);
  // ~max_trajectory_points is 100,000 by default.
  trajectory_.publish(Trajectory(100001, 1.2, 1.0));
  ExpectFollowsNext(-0.2);
}

TEST_F(NodeHostileJointsTest, MillionNamesCommandIsRefusedWhole) {
  sensor_msgs::JointState message;
  message.name.assign(1000000, "shoulder");
  message.position.assign(1000000, 1.1);
  command_.publish(message);
  ExpectFollowsNext(0.5);
}

// 100,000 points (the default limit) for two joints: while the node parses
// and checks them, other calls are answered within 0.5 s, and then the arm
// follows them.
TEST_F(NodeHostileJointsTest, LongTrajectoryWithinLimitsStallsNoCall) {
  ExpectFollowsNext(0.0);
  std::atomic<bool> done{false};
  std::atomic<double> slowest{0.0};
  std::thread prober([&] {
    SimClient prober_client(/*persistent=*/true);
    while (!done) {
      const auto start = std::chrono::steady_clock::now();
      const auto physics = prober_client.GetPhysics();
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (seconds > slowest) slowest = seconds;
      (void)physics;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  });
  trajectory_.publish(Trajectory(100000, 0.7, 1.0));
  const bool reached =
      WaitFor([&] { return std::abs(ShoulderAngle(client_) - 0.7) < 1e-3; }, kTimeout);
  done = true;
  prober.join();
  EXPECT_TRUE(reached) << "shoulder at " << ShoulderAngle(client_) << " rad";
  EXPECT_LT(slowest.load(), 0.5) << "a ~get_physics call waited " << slowest.load() << " s";
  std::printf("slowest ~get_physics while a 100,000-point trajectory was taken in: %.3f s\n",
              slowest.load());
}

TEST_F(NodeHostileJointsTest, PackageUriCannotLeaveItsPackage) {
  rigid_body_sim::Spawn::Request request;
  request.name = "escaped";
  request.urdf_path = "package://rigid_body_sim/../../../../../../etc/hostname";
  request.pose = MakePose(0, 0, 1);
  request.friction = -1.0;
  request.restitution = -1.0;
  const auto reply = client_.Spawn(request);
  EXPECT_FALSE(reply.success);
  EXPECT_NE(reply.message.find("leaves package 'rigid_body_sim'"), std::string::npos)
      << reply.message;
  EXPECT_NE(reply.message.find(request.urdf_path), std::string::npos) << reply.message;
  // The same climb inside a URDF's mesh filename.
  request.urdf_path.clear();
  request.urdf =
      "<robot name='m'><link name='base_link'><collision><geometry><mesh "
      "filename='package://rigid_body_sim/urdf/../../../../../etc/hostname'/></geometry>"
      "</collision></link></robot>";
  const auto mesh_reply = client_.Spawn(request);
  EXPECT_FALSE(mesh_reply.success);
  EXPECT_NE(mesh_reply.message.find("leaves package"), std::string::npos) << mesh_reply.message;
  // '..' that stays inside the package is fine.
  request.urdf.clear();
  request.urdf_path = "package://rigid_body_sim/launch/../urdf/box.urdf";
  const auto inside = client_.Spawn(request);
  EXPECT_TRUE(inside.success) << inside.message;
  client_.Delete("escaped");
}

}  // namespace
}  // namespace rigid_body_sim::test
