// Time stamps under both clocks (run by node_time_stamps_test.test with
// /use_sim_time false and node_time_stamps_sim_test.test with it true): a tf2
// listener looks up every body's transform at its own ros::Time::now(), as
// rviz and robot code do, and gets it without extrapolation errors; ~states
// carries the same clock.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <tf2/exceptions.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "sim_client.h"

namespace rigid_body_sim::test {
namespace {

constexpr double kTimeout = 20.0;  // s of wall time for any single wait

class TimeStampsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(client_.WaitForServices(kTimeout));
    ASSERT_TRUE(ros::param::get("/use_sim_time", use_sim_time_));
    ASSERT_TRUE(client_.SetPaused(true));
    Spawn("stamp_box", BoxUrdf(0.5, 0.5, 0.5, 2.0), MakePose(0.0, 0.0, 30.0), false);
    Spawn("stamp_ball", SphereUrdf(0.2, 1.0), MakePose(2.0, 0.0, 25.0), false);
    Spawn("stamp_shelf", BoxUrdf(1.0, 1.0, 0.1, 5.0), MakePose(-3.0, 0.0, 1.0), true);
    // A listener has nothing from before it subscribed; once it holds each
    // frame, lookups at its now must succeed from then on. Under paused sim
    // time tf goes out only when a step moves time (and the test's clock,
    // our /clock, with it), so a step is taken until the listener, which may
    // still be connecting, has every frame. Polled in wall time: paused sim
    // time would never end a tf2 timeout.
    const auto listener_has_every_frame = [&] {
      if (!client_.Step(1).success) return false;
      return WaitFor(
          [&] {
            for (const std::string& name : spawned_) {
              if (!buffer_.canTransform("world", name + "/base_link", ros::Time(0))) return false;
            }
            return true;
          },
          0.5);
    };
    ASSERT_TRUE(WaitFor(listener_has_every_frame, kTimeout));
  }
  void TearDown() override {
    for (const std::string& name : spawned_) client_.Delete(name);
  }
  void Spawn(const std::string& name, const std::string& urdf, const geometry_msgs::Pose& pose,
             bool is_static) {
    rigid_body_sim::Spawn::Request request;
    request.name = name;
    request.urdf = urdf;
    request.pose = pose;
    request.is_static = is_static;
    request.friction = -1.0;
    request.restitution = -1.0;
    const auto response = client_.Spawn(request);
    ASSERT_TRUE(response.success) << response.message;
    spawned_.push_back(name);
  }
  // Looks every frame up at the listener's now; fails on any tf2 exception.
  void LookUpEveryFrameAtNow() {
    for (const std::string& name : spawned_) {
      const std::string frame = name + "/base_link";
      const ros::Time now = ros::Time::now();
      try {
        // Under sim time the timeout runs in sim time, which stands still
        // while paused; there tf already holds the paused instant.
        const auto transform = buffer_.lookupTransform("world", frame, now, ros::Duration(2.0));
        const auto state = client_.GetState(name);
        ASSERT_TRUE(state.success) << state.message;
        // Paused, so interpolation has nothing to blur: the pose is exact.
        if (paused_) {
          EXPECT_NEAR(transform.transform.translation.z, state.pose.position.z, 1e-9) << frame;
        }
      } catch (const tf2::TransformException& error) {
        ADD_FAILURE() << frame << " at " << now << " (use_sim_time " << use_sim_time_
                      << "): " << error.what();
      }
    }
  }

  SimClient client_;
  ros::NodeHandle node_{"/rigid_body_sim"};
  Latest<rigid_body_sim::ModelStates> states_{node_, "states"};
  tf2_ros::Buffer buffer_;
  tf2_ros::TransformListener listener_{buffer_};
  std::vector<std::string> spawned_;
  bool use_sim_time_ = false;
  bool paused_ = true;
};

TEST_F(TimeStampsTest, ListenerGetsEveryBodyAtNowWhilePaused) {
  LookUpEveryFrameAtNow();
  // Still there a second later: under wall time tf keeps coming while paused.
  ros::WallDuration(1.0).sleep();
  LookUpEveryFrameAtNow();
}

TEST_F(TimeStampsTest, ListenerGetsEveryBodyAtNowWhileRunning) {
  ASSERT_TRUE(client_.SetPaused(false));
  paused_ = false;
  for (int i = 0; i < 10; ++i) {
    LookUpEveryFrameAtNow();
    ros::WallDuration(0.1).sleep();
  }
}

TEST_F(TimeStampsTest, StatesAreStampedWithTheNodesClock) {
  const auto stepped = client_.Step(24);
  ASSERT_TRUE(stepped.success) << stepped.message;
  const auto states = states_.Next(kTimeout);
  ASSERT_TRUE(states.has_value());
  if (use_sim_time_) {
    // Paused: sim time stands at the step's end.
    EXPECT_NEAR(states->header.stamp.toSec(), stepped.sim_time, 1e-9);
  } else {
    // Wall time, taken when the message was built: within the publish
    // period (20 ms) plus delivery of the test's own clock.
    const double age = (ros::Time::now() - states->header.stamp).toSec();
    EXPECT_GE(age, 0.0);
    EXPECT_LT(age, 0.5);
  }
}

}  // namespace
}  // namespace rigid_body_sim::test
