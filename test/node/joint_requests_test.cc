// The joint topics' parsing (joint_requests.h): refusals name the field and
// change nothing; what is accepted is what the message said; a long
// trajectory is planned without the world and sampled by bisection.
#include "rigid_body_sim/node/joint_requests.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

namespace rigid_body_sim::node {
namespace {

ModelJoints Joints() {
  ModelJoints joints;
  joints.model = "arm";
  joints.names = {"shoulder", "slide", "finger"};
  joints.prismatic = {false, true, true};
  joints.leaders = {"", "", "slide"};
  for (std::size_t k = 0; k < joints.names.size(); ++k) {
    joints.index.emplace(joints.names[k], static_cast<int>(k));
  }
  return joints;
}

void ExpectRefused(const physics::Status& status, const std::string& words) {
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find(words), std::string::npos) << status.message();
}

TEST(JointRequestsTest, CommandRefusalsNameTheField) {
  const RequestLimits limits;
  const ModelJoints joints = Joints();
  ExpectRefused(ParseJointCommand(joints, {{}, {}, {}, {}}, limits).status(), "name is empty");
  ExpectRefused(ParseJointCommand(joints, {{"elbow"}, {0.1}, {}, {}}, limits).status(),
                "model 'arm' has no movable joint 'elbow'");
  ExpectRefused(ParseJointCommand(joints, {{"finger"}, {0.1}, {}, {}}, limits).status(),
                "joint 'finger' mimics 'slide'");
  ExpectRefused(
      ParseJointCommand(joints, {{"slide", "slide"}, {0.1, 0.2}, {}, {}}, limits).status(),
      "joint 'slide' is named twice");
  ExpectRefused(ParseJointCommand(joints, {{"slide"}, {0.1, 0.2}, {}, {}}, limits).status(),
                "one per name");
  ExpectRefused(ParseJointCommand(joints, {{"shoulder"}, {2e4}, {}, {}}, limits).status(),
                "joint 'shoulder'");
  // A prismatic joint's speed is held to the linear limit.
  RequestLimits slow = limits;
  slow.max_linear_speed = 1.0;
  ExpectRefused(ParseJointCommand(joints, {{"slide"}, {}, {2.0}, {}}, slow).status(),
                "joint 'slide'");
  EXPECT_TRUE(ParseJointCommand(joints, {{"shoulder"}, {}, {2.0}, {}}, slow).ok());
}

TEST(JointRequestsTest, CommandTakesEachValueAndItsMode) {
  const auto parsed =
      ParseJointCommand(Joints(), {{"slide", "shoulder"}, {}, {0.5, -1.5}, {3.0, 4.0}}, {});
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  ASSERT_EQ(parsed->size(), 2u);
  EXPECT_EQ((*parsed)[0].first, 1);
  EXPECT_EQ((*parsed)[1].first, 0);
  EXPECT_EQ((*parsed)[0].second.mode, physics::JointCommandMode::kVelocity);
  EXPECT_EQ((*parsed)[1].second.velocity, -1.5);
  EXPECT_EQ((*parsed)[1].second.effort, 4.0);
}

JointTrajectoryRequest Sine(int points, double duration) {
  JointTrajectoryRequest request;
  request.joint_names = {"shoulder"};
  for (int i = 0; i < points; ++i) {
    const double t = duration * (i + 1) / points;
    request.points.push_back({{std::sin(t)}, {std::cos(t)}, t});
  }
  return request;
}

TEST(JointRequestsTest, TrajectoryPastThePointLimitIsRefusedByName) {
  RequestLimits limits;
  limits.max_trajectory_points = 10;
  ExpectRefused(ParseJointTrajectory(Joints(), Sine(11, 1.0), limits).status(),
                "11 points, more than ~max_trajectory_points 10");
  EXPECT_TRUE(ParseJointTrajectory(Joints(), Sine(10, 1.0), limits).ok());
  JointTrajectoryRequest far = Sine(5, 1.0);
  far.points[3].positions[0] = 1e5;
  ExpectRefused(ParseJointTrajectory(Joints(), far, limits).status(),
                "point 3 joint 'shoulder' position");
}

// 100,000 Hermite segments of sin t with its exact slopes: the error of a
// cubic Hermite interpolant is below h^4 / 384 max|f''''| (de Boor 1978,
// ch. IV), 3e-21 at h = 1e-4, so each sample is sin t to rounding, and
// bisection finds the right segment at every time.
TEST(JointRequestsTest, LongTrajectorySamplesItsCurveEverywhere) {
  auto parsed = ParseJointTrajectory(Joints(), Sine(100000, 10.0), RequestLimits());
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  ASSERT_TRUE(parsed.value().plan.Begin({0.0, {0.0}, {1.0}}).ok());
  const JointTrajectory& plan = parsed->plan;
  for (double t = 0.0; t < 10.0; t += 0.0123) {
    const TrajectorySample sample = plan.Sample(t);
    EXPECT_NEAR(sample.positions[0], std::sin(t), 1e-12) << t;
    EXPECT_NEAR(sample.velocities[0], std::cos(t), 1e-8) << t;
  }
  EXPECT_EQ(plan.Sample(std::nan("")).positions[0], 0.0);  // the start
}

// The first point's velocity, when left out, is the mean of the slopes
// from the start and to the next point: Plan cannot know it, Begin does.
TEST(JointRequestsTest, FirstPointsEstimateUsesTheStart) {
  JointTrajectoryRequest request;
  request.joint_names = {"shoulder"};
  request.points = {{{1.0}, {}, 1.0}, {{3.0}, {}, 2.0}};
  auto parsed = ParseJointTrajectory(Joints(), request, RequestLimits());
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  ASSERT_TRUE(parsed.value().plan.Begin({0.0, {0.0}, {0.0}}).ok());
  EXPECT_DOUBLE_EQ(parsed->plan.Sample(1.0).velocities[0], 0.5 * (1.0 + 2.0));
  EXPECT_EQ(parsed->plan.Sample(2.0).velocities[0], 0.0);
  EXPECT_EQ(parsed->plan.Sample(5.0).positions[0], 3.0);
}

// Points 1e-300 s apart would give slopes of 1e304 rad/s and samples that
// overflow (found by joint_requests_fuzzer): points must be at least
// kMinPointGap apart, and so every sample is finite.
TEST(JointRequestsTest, PointsCloserThanTheLeastGapAreRefused) {
  JointTrajectoryRequest request;
  request.joint_names = {"shoulder"};
  request.points = {{{1.0}, {}, 0.5}, {{-1.0}, {}, 0.5 + 1e-300}, {{1.0}, {}, 1.0}};
  ExpectRefused(ParseJointTrajectory(Joints(), request, RequestLimits()).status(),
                "point 1 time_from_start");
  request.points = {{{1.0}, {}, 1e-9}};
  ExpectRefused(ParseJointTrajectory(Joints(), request, RequestLimits()).status(),
                "point 0 time_from_start");
  // 1.5 gaps apart: the closest points the rule lets through, up to
  // rounding, swinging across the whole position range.
  const double gap = 1.5 * JointTrajectory::kMinPointGap;
  request.points = {{{1e4}, {}, 0.5}, {{-1e4}, {}, 0.5 + gap}, {{1e4}, {}, 0.5 + 2 * gap}};
  auto parsed = ParseJointTrajectory(Joints(), request, RequestLimits());
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  ASSERT_TRUE(parsed.value().plan.Begin({0.0, {0.0}, {0.0}}).ok());
  for (double t = 0.5; t < 0.5 + 2.5 * gap; t += 1e-7) {
    const TrajectorySample sample = parsed->plan.Sample(t);
    EXPECT_TRUE(std::isfinite(sample.positions[0]) && std::isfinite(sample.velocities[0])) << t;
  }
}

// Far from 0, t + kMinPointGap rounds back to t: two points at 8.9e194 s
// passed the gap rule and Sample divided 0 by 0 (joint_requests_fuzzer).
// A point later than a ROS duration's span (2^31 s) is refused, and at that
// span points kMinPointGap apart still sample finite and in order.
TEST(JointRequestsTest, PointsBeyondTheLatestTimeAreRefused) {
  JointTrajectoryRequest request;
  request.joint_names = {"shoulder"};
  request.points = {{{1.0}, {}, 8.9e194}, {{-1.0}, {}, 8.9e194}};
  ExpectRefused(ParseJointTrajectory(Joints(), request, RequestLimits()).status(),
                "point 0 time_from_start");
  request.points = {{{1.0}, {}, 1.0},
                    {{-1.0}, {}, std::nextafter(JointTrajectory::kMaxPointTime, 1e300)}};
  ExpectRefused(ParseJointTrajectory(Joints(), request, RequestLimits()).status(),
                "point 1 time_from_start");
  // 1.5 gaps: the doubles near 2^31 are 4.8e-7 s apart, so last - gap
  // itself rounds to less than a gap before last.
  const double last = JointTrajectory::kMaxPointTime;
  const double gap = 1.5 * JointTrajectory::kMinPointGap;
  request.points = {{{1e4}, {}, last - gap}, {{-1e4}, {}, last}};
  auto parsed = ParseJointTrajectory(Joints(), request, RequestLimits());
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  ASSERT_TRUE(parsed.value().plan.Begin({0.0, {0.0}, {0.0}}).ok());
  for (const double t : {last - 2 * gap, last - gap, last - 0.5 * gap, last}) {
    const TrajectorySample sample = parsed->plan.Sample(t);
    EXPECT_TRUE(std::isfinite(sample.positions[0]) && std::isfinite(sample.velocities[0])) << t;
  }
  EXPECT_EQ(parsed->plan.Sample(last).positions[0], -1e4);
}

}  // namespace
}  // namespace rigid_body_sim::node
