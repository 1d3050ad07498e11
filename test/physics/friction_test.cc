// Resting contact forces and Coulomb friction against analytic answers.
#include <cmath>

#include <gtest/gtest.h>

#include "scene.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::AddGround;
using testing::AddSphere;
using testing::BoxSpec;
using testing::MakeMaterial;
using testing::SphereSpec;
using testing::Translation;

constexpr double kG = 9.81;
constexpr double kMu = 0.5;
constexpr double kDegree = M_PI / 180.0;

// A box at rest on the ground: the resting-contact forces carry its weight,
// sum f_i = m g (Baraff 1997, "Rigid Body
// Simulation II", section 9, eqs. (9-5)-(9-7)), and it stays put.
TEST(RestingContactTest, BoxOnGroundCarriesItsWeightAndStaysPut) {
  World world;
  const BodyId ground = AddGround(&world, MakeMaterial(kMu, 0.0));
  BoxSpec spec;
  spec.mass = 2.5;
  spec.world_from_body = Translation(0.3, -0.2, 0.5);
  spec.material = MakeMaterial(kMu, 0.0);
  const BodyId box = AddBox(&world, spec);
  const Vec3 start = world.GetPose(box).translation;
  double max_drift = 0.0;
  for (int step = 0; step < 240 * 10; ++step) {
    world.Step();
    max_drift = std::max(max_drift, (world.GetPose(box).translation - start).norm());
    if (step == 240 || step == 240 * 10 - 1) {
      double total = 0.0;
      int resting = 0;
      for (const ContactReport& contact : world.contacts()) {
        if (contact.body_a == box && contact.body_b == ground) {
          total += contact.normal_force * contact.normal_world.z();
          resting += contact.type == ContactType::kResting;
        }
      }
      EXPECT_GE(resting, 3) << "step " << step;
      EXPECT_NEAR(total / (spec.mass * kG), 1.0, 0.01) << "step " << step;
    }
  }
  EXPECT_LT(max_drift, 1e-4);
}

// Distance a box slides from rest down a slope in time t:
// s = 1/2 g (sin(theta) - mu cos(theta)) t^2, or 0 when tan(theta) <= mu.
double SlideDistance(double theta, double t) {
  return std::max(0.0, 0.5 * kG * (std::sin(theta) - kMu * std::cos(theta)) * t * t);
}

enum class Incline { kTiltedRamp, kTiltedGravity };

struct InclineCase {
  double theta;  // rad
  Incline incline;
};

class InclineTest : public ::testing::TestWithParam<InclineCase> {};

TEST_P(InclineTest, SticksOrSlidesAsCoulombSays) {
  const InclineCase param = GetParam();
  const double theta = param.theta;
  WorldSettings settings;
  Vec3 downhill;
  Pose box_pose;
  if (param.incline == Incline::kTiltedGravity) {
    settings.gravity = kG * Vec3(std::sin(theta), 0.0, -std::cos(theta));
    downhill = Vec3::UnitX();
    box_pose = Translation(0, 0, 0.5);
  }
  World world(settings);
  if (param.incline == Incline::kTiltedGravity) {
    AddGround(&world, MakeMaterial(kMu, 0.0));
  } else {
    // A long static box tilted about y; its top face has normal
    // (sin, 0, cos) and falls along (cos, 0, -sin).
    const Quat tilt(Eigen::AngleAxisd(theta, Vec3::UnitY()));
    BoxSpec ramp;
    ramp.size = Vec3(30.0, 4.0, 1.0);
    ramp.is_static = true;
    ramp.world_from_body.translation = Vec3(0, 0, 10.0);
    ramp.world_from_body.rotation = tilt;
    ramp.material = MakeMaterial(kMu, 0.0);
    AddBox(&world, ramp);
    const Vec3 normal = tilt * Vec3::UnitZ();
    downhill = tilt * Vec3::UnitX();
    box_pose.translation = ramp.world_from_body.translation + normal * 1.0;
    box_pose.rotation = tilt;
  }
  BoxSpec box;
  box.world_from_body = box_pose;
  box.material = MakeMaterial(kMu, 0.0);
  const BodyId id = AddBox(&world, box);
  const Vec3 start = world.GetPose(id).translation;
  const double t = 2.0;
  for (int step = 0; step < static_cast<int>(std::lround(t / settings.time_step)); ++step) {
    world.Step();
  }
  const Vec3 moved = world.GetPose(id).translation - start;
  const double expected = SlideDistance(theta, t);
  if (expected == 0.0) {
    EXPECT_LT(moved.norm(), 1e-3) << "moved " << moved.transpose();
  } else {
    EXPECT_NEAR(moved.dot(downhill) / expected, 1.0, 0.03)
        << "slid " << moved.dot(downhill) << " m, expected " << expected << " m";
  }
}

const double kFrictionAngle = std::atan(kMu);

INSTANTIATE_TEST_SUITE_P(
    Slopes, InclineTest,
    ::testing::Values(InclineCase{kFrictionAngle - 2 * kDegree, Incline::kTiltedRamp},
                      InclineCase{kFrictionAngle + 2 * kDegree, Incline::kTiltedRamp},
                      InclineCase{35 * kDegree, Incline::kTiltedRamp},
                      InclineCase{kFrictionAngle - 2 * kDegree, Incline::kTiltedGravity},
                      InclineCase{kFrictionAngle + 2 * kDegree, Incline::kTiltedGravity},
                      InclineCase{35 * kDegree, Incline::kTiltedGravity},
                      // Slower than the sleep threshold (0.05 m/s) for its
                      // first 1.3 s: it must not fall asleep mid-slide.
                      InclineCase{kFrictionAngle + 0.2 * kDegree, Incline::kTiltedRamp},
                      InclineCase{kFrictionAngle + 0.2 * kDegree, Incline::kTiltedGravity}));

// A box launched along flat ground at v0 stops after v0^2 / (2 mu g).
TEST(FrictionTest, LaunchedBoxStopsAfterAnalyticDistance) {
  World world;
  AddGround(&world, MakeMaterial(kMu, 0.0));
  BoxSpec spec;
  spec.world_from_body = Translation(0, 0, 0.5);
  spec.material = MakeMaterial(kMu, 0.0);
  const double v0 = 3.0;
  spec.linear_velocity = Vec3(v0, 0, 0);
  const BodyId box = AddBox(&world, spec);
  for (int step = 0; step < 240 * 2; ++step) world.Step();
  EXPECT_LT(world.GetLinearVelocity(box).norm(), 1e-3);
  const double expected = v0 * v0 / (2.0 * kMu * kG);
  EXPECT_NEAR(world.GetPose(box).translation.x() / expected, 1.0, 0.03);
  EXPECT_LT(std::abs(world.GetPose(box).translation.y()), 1e-3);
}

// Sliding in a direction between the tangent axes: a circular friction cone
// has no preferred direction, so the stopping distance and the straight path
// do not depend on the heading.
TEST(FrictionTest, StoppingDistanceDoesNotDependOnHeading) {
  const double v0 = 3.0;
  const double expected = v0 * v0 / (2.0 * kMu * kG);
  for (double heading : {0.0, 0.3, M_PI / 4, 1.2, 2.0}) {
    World world;
    AddGround(&world, MakeMaterial(kMu, 0.0));
    BoxSpec spec;
    spec.world_from_body = Translation(0, 0, 0.5);
    spec.world_from_body.rotation = Quat(Eigen::AngleAxisd(heading, Vec3::UnitZ()));
    spec.material = MakeMaterial(kMu, 0.0);
    const Vec3 direction(std::cos(heading), std::sin(heading), 0.0);
    spec.linear_velocity = v0 * direction;
    const BodyId box = AddBox(&world, spec);
    for (int step = 0; step < 240 * 2; ++step) world.Step();
    const Vec3 moved = world.GetPose(box).translation - Vec3(0, 0, 0.5);
    EXPECT_NEAR(moved.dot(direction) / expected, 1.0, 0.03) << "heading " << heading;
    EXPECT_LT(moved.cross(direction).norm(), 0.01 * expected) << "heading " << heading;
  }
}

// A ball launched along the ground without spin slides until friction has
// made it roll: mu m g slows it while mu m g r / (2/5 m r^2) spins it up, so
// v = r omega after t = 2 v0 / (7 mu g), at v = 5/7 v0, which it keeps
// (a rigid ball on a rigid plane has no rolling resistance). The rolling
// speed is exact in discrete time too: friction, the only horizontal force,
// acts at the contact point, so the angular momentum about it is conserved.
// The distance is off by the part of a step the slip ends within.
TEST(FrictionTest, SlidingBallStartsRollingAtFiveSeventhsOfItsSpeed) {
  World world;
  AddGround(&world, MakeMaterial(kMu, 0.0));
  SphereSpec spec;
  spec.radius = 0.2;
  spec.world_from_body = Translation(0, 0, spec.radius);
  spec.material = MakeMaterial(kMu, 0.0);
  const double v0 = 2.0;
  spec.linear_velocity = Vec3(v0, 0, 0);
  const BodyId ball = AddSphere(&world, spec);
  const double slip_time = 2.0 * v0 / (7.0 * kMu * kG);
  const double slip_distance = v0 * slip_time - 0.5 * kMu * kG * slip_time * slip_time;
  const double t = 1.0;
  for (int step = 0; step < 240; ++step) world.Step();
  EXPECT_NEAR(world.GetLinearVelocity(ball).x() / (5.0 / 7.0 * v0), 1.0, 1e-6);
  EXPECT_NEAR(world.GetAngularVelocity(ball).y() * spec.radius / (5.0 / 7.0 * v0), 1.0, 1e-6);
  const double expected = slip_distance + 5.0 / 7.0 * v0 * (t - slip_time);
  EXPECT_NEAR(world.GetPose(ball).translation.x() / expected, 1.0, 2e-3);
}

}  // namespace
}  // namespace rigid_body_sim::physics
