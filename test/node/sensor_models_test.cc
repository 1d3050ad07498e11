// The sensor models against closed forms: an IMU at rest, in free fall and
// on a turntable; a laser's angles and its ranges' noise; a subtree's
// reaction wrench; a differential drive's wheels and odometry.
#include "rigid_body_sim/node/sensor_models.h"

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace rigid_body_sim::node {
namespace {

using physics::Quat;
using physics::Vec3;

constexpr double kDt = 1.0 / 240.0;
const Vec3 kGravity(0, 0, -9.81);

FrameState At(const Vec3& position, const Quat& rotation, const Vec3& linear, const Vec3& angular) {
  FrameState state;
  state.world_from_frame.translation = position;
  state.world_from_frame.rotation = rotation;
  state.linear_velocity = linear;
  state.angular_velocity = angular;
  return state;
}

TEST(ImuModelTest, AtRestReadsGravityUpAndNoRate) {
  const Quat tilted(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  const FrameState rest = At(Vec3(1, 2, 3), tilted, Vec3::Zero(), Vec3::Zero());
  const ImuReading reading = MeasureImu(rest, rest, kDt, kGravity);
  const Vec3 up_in_sensor = tilted.conjugate() * Vec3(0, 0, 9.81);
  EXPECT_LT((reading.linear_acceleration_sensor - up_in_sensor).norm(), 1e-12);
  EXPECT_LT(reading.angular_velocity_sensor.norm(), 1e-15);
  EXPECT_TRUE(reading.world_from_sensor.isApprox(tilted, 1e-15));
}

TEST(ImuModelTest, InFreeFallReadsNoAcceleration) {
  const Quat q(Eigen::AngleAxisd(1.1, Vec3::UnitY()));
  const FrameState before = At(Vec3::Zero(), q, Vec3(1, 0, 2), Vec3::Zero());
  const FrameState after = At(Vec3::Zero(), q, Vec3(1, 0, 2) + kGravity * kDt, Vec3::Zero());
  EXPECT_LT(MeasureImu(before, after, kDt, kGravity).linear_acceleration_sensor.norm(), 1e-12);
}

// A sensor r from the axis of a turntable turning at w about z, facing
// along its radius: it reads w about its z and w^2 r toward the axis (its
// -x), exactly, whatever the step.
TEST(ImuModelTest, OnATurntableReadsTheRateAndTheCentripetalAcceleration) {
  const double w = 2.0;
  const double r = 0.7;
  const auto state_at = [&](double angle) {
    const Quat q(Eigen::AngleAxisd(angle, Vec3::UnitZ()));
    const Vec3 position = q * Vec3(r, 0, 0);
    return At(position, q, Vec3(0, 0, w).cross(position), Vec3(0, 0, w));
  };
  const ImuReading reading = MeasureImu(state_at(0.4), state_at(0.4 + w * kDt), kDt, Vec3::Zero());
  EXPECT_NEAR(reading.angular_velocity_sensor.z(), w, 1e-12);
  EXPECT_NEAR(reading.linear_acceleration_sensor.x(), -w * w * r, 1e-12);
  EXPECT_NEAR(reading.linear_acceleration_sensor.y(), 0.0, 1e-12);
  EXPECT_NEAR(reading.linear_acceleration_sensor.z(), 0.0, 1e-12);
}

io::LaserSensor Lds() {
  io::LaserSensor laser;
  laser.horizontal_samples = 360;
  laser.min_angle = 0.0;
  laser.max_angle = 6.28319;
  laser.range_min = 0.12;
  laser.range_max = 3.5;
  return laser;
}

TEST(LaserModelTest, RaysSpanTheAnglesAndStartAtTheMinimumRange) {
  const io::LaserSensor laser = Lds();
  const std::vector<Vec3> directions = LaserDirections(laser);
  ASSERT_EQ(directions.size(), 360u);
  const double step = 6.28319 / 359.0;
  EXPECT_DOUBLE_EQ(LaserAngleIncrement(laser), step);
  EXPECT_NEAR(std::atan2(directions[90].y(), directions[90].x()), 90 * step, 1e-12);
  physics::Pose world_from_sensor;
  world_from_sensor.translation = Vec3(1, 1, 0.2);
  world_from_sensor.rotation = Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()));
  const std::vector<physics::Ray> rays = LaserRays(laser, directions, world_from_sensor);
  EXPECT_LT((rays[0].origin - Vec3(1, 1.12, 0.2)).norm(), 1e-12);
  EXPECT_LT((rays[0].direction - Vec3(0, 1, 0)).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(rays[0].max_distance, 3.5 - 0.12);
}

TEST(LaserModelTest, RangesFollowRep117AndTheNoiseHasItsDeviation) {
  io::LaserSensor laser = Lds();
  std::vector<physics::RayHit> hits(10000);
  for (physics::RayHit& hit : hits) {
    hit.hit = true;
    hit.distance = 1.88;  // a wall 2 m away
  }
  hits[0].hit = false;
  SensorNoise noise(7);
  std::vector<double> exact = LaserRanges(laser, hits, &noise);
  EXPECT_EQ(exact[0], std::numeric_limits<double>::infinity());
  EXPECT_DOUBLE_EQ(exact[1], 2.0);

  laser.noise.stddev = 0.01;
  const std::vector<double> noisy = LaserRanges(laser, hits, &noise);
  double sum = 0.0;
  double squares = 0.0;
  for (std::size_t i = 1; i < noisy.size(); ++i) {
    sum += noisy[i] - 2.0;
    squares += (noisy[i] - 2.0) * (noisy[i] - 2.0);
  }
  const double n = static_cast<double>(noisy.size() - 1);
  const double deviation = std::sqrt(squares / n - (sum / n) * (sum / n));
  EXPECT_NEAR(deviation, 0.01, 0.05 * 0.01);
  // The same seed gives the same readings.
  SensorNoise again(7);
  LaserRanges(Lds(), hits, &again);
  EXPECT_EQ(LaserRanges(laser, hits, &again), noisy);
}

// Two 1 kg links hanging at rest below a joint at the origin, their
// centres at (0.5, 0, 0) and (1, 0, 0): the joint holds 2 g up and the
// moment of their weight, (0, 0.5 + 1, 0) g about y.
TEST(ForceTorqueModelTest, AHeldArmCarriesTheWeightAndMomentOfItsLinks) {
  SubtreeMotion motion;
  motion.dt = kDt;
  motion.gravity = kGravity;
  for (const double x : {0.5, 1.0}) {
    SubtreeLink link;
    link.mass = 1.0;
    link.inertia_com_link = physics::Mat3::Identity() * 0.01;
    link.before = At(Vec3(x, 0, 0), Quat::Identity(), Vec3::Zero(), Vec3::Zero());
    link.after = link.before;
    motion.links.push_back(link);
  }
  const Wrench wrench = SubtreeReaction(motion);
  EXPECT_LT((wrench.force - Vec3(0, 0, 2 * 9.81)).norm(), 1e-12);
  EXPECT_LT((wrench.torque - Vec3(0, -1.5 * 9.81, 0)).norm(), 1e-12);
  // A table under the tip takes 3 N of it.
  motion.external.push_back({Vec3(0, 0, 3), Vec3(1, 0, 0)});
  const Wrench relieved = SubtreeReaction(motion);
  EXPECT_LT((relieved.force - Vec3(0, 0, 2 * 9.81 - 3)).norm(), 1e-12);
  EXPECT_LT((relieved.torque - Vec3(0, -1.5 * 9.81 + 3, 0)).norm(), 1e-12);
}

TEST(DiffDriveModelTest, WheelSpeedsRampAndLegacyModeSwapsTheSides) {
  io::DiffDrive drive;
  drive.wheel_separation = 0.16;
  drive.legacy_mode = false;
  const WheelSpeeds speeds = WheelSpeedsForTwist(drive, 0.1, 1.0);
  EXPECT_DOUBLE_EQ(speeds.left, 0.1 - 0.08);
  EXPECT_DOUBLE_EQ(speeds.right, 0.1 + 0.08);
  drive.legacy_mode = true;
  EXPECT_DOUBLE_EQ(WheelSpeedsForTwist(drive, 0.1, 1.0).left, 0.1 + 0.08);
  EXPECT_DOUBLE_EQ(RampToward(0.0, 0.1, 1.0, kDt), kDt);
  EXPECT_DOUBLE_EQ(RampToward(0.099, 0.1, 1.0, kDt), 0.1);
  EXPECT_DOUBLE_EQ(RampToward(0.0, -0.1, 0.0, kDt), -0.1);
}

// Wheels turning at constant rates drive the base on a circle of radius
// v / w: after one full turn the encoders' odometry is back at the start,
// and a quarter turn ends at (R, R).
TEST(DiffDriveModelTest, EncoderOdometryFollowsTheArcExactly) {
  io::DiffDrive drive;
  drive.wheel_separation = 0.16;
  drive.wheel_diameter = 0.066;
  const double v = 0.1;
  const double w = 0.5;
  const double r = 0.033;
  const double left_rate = (v - w * 0.08) / r;
  const double right_rate = (v + w * 0.08) / r;
  PlanarOdometry odometry;
  const double quarter = M_PI / 2 / w;
  const int steps = 240;
  const double dt = quarter / steps;
  for (int i = 0; i < steps; ++i) {
    IntegrateWheels(drive, left_rate * dt, right_rate * dt, dt, &odometry);
  }
  const double radius = v / w;
  EXPECT_NEAR(odometry.x, radius, 1e-12);
  EXPECT_NEAR(odometry.y, radius, 1e-12);
  EXPECT_NEAR(odometry.theta, M_PI / 2, 1e-12);
  EXPECT_NEAR(odometry.linear, v, 1e-12);
  EXPECT_NEAR(odometry.angular, w, 1e-12);
}

}  // namespace
}  // namespace rigid_body_sim::node
