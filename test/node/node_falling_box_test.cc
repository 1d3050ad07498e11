// Acceptance 1: a 1 m box dropped from z = 2 comes to rest on the ground with
// its centre at z = 0.5, as tf sees it.
#include <gtest/gtest.h>

#include <cmath>

#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "sim_client.h"

namespace rigid_body_sim::test {
namespace {

TEST(FallingBoxTest, BoxRestsOnTheGroundAtHalfItsHeight) {
  SimClient client;
  ASSERT_TRUE(client.WaitForServices(20.0));
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  const auto spawned = client.SpawnUrdf("box1", BoxUrdf(1.0, 1.0, 1.0, 1.0), MakePose(0, 0, 2));
  ASSERT_TRUE(spawned.success) << spawned.message;
  // At rest: below 1 mm/s and 1 mrad/s, after the 1.5 m fall (0.55 s) is over.
  const auto at_rest = [&] {
    const auto state = client.GetState("box1");
    const double speed =
        std::hypot(state.twist.linear.x, state.twist.linear.y, state.twist.linear.z);
    const double spin =
        std::hypot(state.twist.angular.x, state.twist.angular.y, state.twist.angular.z);
    return state.success && state.pose.position.z < 1.0 && speed < 1e-3 && spin < 1e-3;
  };
  ASSERT_TRUE(WaitFor(at_rest, 60.0));
  ASSERT_TRUE(client.SetPaused(true));
  // While paused, tf carries a pose only when a step makes it new; the
  // sleeping box stays put, so one step is taken until tf has its pose.
  geometry_msgs::TransformStamped transform;
  const auto tf_has_step = [&] {
    const auto stepped = client.Step(1);
    return stepped.success &&
           WaitFor(
               [&] {
                 if (!buffer.canTransform("world", "box1/base_link", ros::Time(0))) {
                   return false;
                 }
                 transform = buffer.lookupTransform("world", "box1/base_link", ros::Time(0));
                 return std::abs(transform.header.stamp.toSec() - stepped.sim_time) < 1e-6;
               },
               1.0);
  };
  ASSERT_TRUE(WaitFor(tf_has_step, 20.0));
  EXPECT_NEAR(transform.transform.translation.z, 0.5, 0.002);
  EXPECT_NEAR(transform.transform.translation.x, 0.0, 0.002);
  EXPECT_NEAR(transform.transform.translation.y, 0.0, 0.002);
}

}  // namespace
}  // namespace rigid_body_sim::test
