// Motion under forces and torques that are constant over each step is exact
// to second order: a spin-up under a constant torque, and sliding against
// kinetic friction on flat ground and down a slope, against their closed
// forms after 2 s.
#include <cmath>

#include <gtest/gtest.h>

#include "scene.h"

namespace rigid_body_sim::physics::testing {
namespace {

constexpr double kG = 9.81;  // m/s^2
constexpr double kSeconds = 2.0;
constexpr double kRelative = 1e-4;

int StepsIn(const World& world, double seconds) {
  return static_cast<int>(std::lround(seconds / world.settings().time_step));
}

// The rotation angle of q about `axis` (q a rotation about that axis).
double AngleAbout(const Quat& q, const Vec3& axis) {
  return 2.0 * std::atan2(q.vec().dot(axis), q.w());
}

// A body at rest with a constant torque tau about a principal axis turns by
// theta = tau t^2 / (2 I): for a cube about any axis, for a box about each
// of its principal axes. Theta stays below pi so the angle is unambiguous.
TEST(ConstantForceTest, ConstantTorqueSpinsUpAsTauTSquaredOverTwoI) {
  struct Case {
    Vec3 size;
    Vec3 axis;
  };
  for (const Case& c :
       {Case{Vec3(0.2, 0.2, 0.2), Vec3(1, 2, 2) / 3.0}, Case{Vec3(0.4, 0.2, 0.1), Vec3::UnitX()},
        Case{Vec3(0.4, 0.2, 0.1), Vec3::UnitZ()}}) {
    SCOPED_TRACE(c.size.transpose());
    WorldSettings settings;
    settings.gravity = Vec3::Zero();
    World world(settings);
    BoxSpec spec;
    spec.size = c.size;
    spec.mass = 2.0;
    const BodyId box = AddBox(&world, spec);
    const MassProperties properties = BoxMassProperties(spec.mass / spec.size.prod(), spec.size);
    const double inertia = c.axis.dot(properties.inertia_about_com * c.axis);
    const double torque = 0.3 * inertia;  // rad/s^2 of angular acceleration: 0.3
    for (int step = 0; step < StepsIn(world, kSeconds); ++step) {
      ASSERT_TRUE(world.ApplyTorque(box, torque * c.axis).ok());
      world.Step();
    }
    const double expected = torque * kSeconds * kSeconds / (2.0 * inertia);
    EXPECT_NEAR(AngleAbout(world.GetPose(box).rotation, c.axis) / expected, 1.0, kRelative);
    EXPECT_NEAR(world.GetAngularVelocity(box).dot(c.axis), torque * kSeconds / inertia,
                kRelative * torque * kSeconds / inertia);
  }
}

// A box launched at v0 along flat ground decelerates at mu g: after t (before
// it stops) it has gone v0 t - mu g t^2 / 2.
TEST(ConstantForceTest, SlidingBoxFollowsKineticFrictionOnFlatGround) {
  WorldSettings settings;
  settings.sleep.enabled = false;
  World world(settings);
  const double mu = 0.3;
  AddGround(&world, MakeMaterial(mu, 0.0));
  BoxSpec spec;
  spec.size = Vec3(0.4, 0.4, 0.2);
  spec.world_from_body = Translation(0, 0, 0.1);
  spec.material = MakeMaterial(mu, 0.0);
  spec.linear_velocity = Vec3(10.0, 0, 0);
  const BodyId box = AddBox(&world, spec);
  for (int step = 0; step < StepsIn(world, kSeconds); ++step) world.Step();
  const double expected = 10.0 * kSeconds - 0.5 * mu * kG * kSeconds * kSeconds;
  EXPECT_NEAR(world.GetPose(box).translation.x() / expected, 1.0, kRelative);
  EXPECT_NEAR(world.GetLinearVelocity(box).x(), 10.0 - mu * kG * kSeconds,
              kRelative * (10.0 - mu * kG * kSeconds));
}

// Down a 40 degree slope with mu = 0.5 the box slides from rest with
// a = g (sin(theta) - mu cos(theta)): s = a t^2 / 2.
TEST(ConstantForceTest, SlidingBoxFollowsKineticFrictionDownASlope) {
  const double theta = 40.0 * kPi / 180.0;
  const double mu = 0.5;
  World world;
  const Quat tilt(Eigen::AngleAxisd(theta, Vec3::UnitY()));
  BoxSpec ramp;
  ramp.size = Vec3(60.0, 4.0, 1.0);
  ramp.is_static = true;
  ramp.world_from_body = Pose{Vec3(0, 0, 20.0), tilt};
  ramp.material = MakeMaterial(mu, 0.0);
  AddBox(&world, ramp);
  const Vec3 normal = tilt * Vec3::UnitZ();
  const Vec3 downhill = tilt * Vec3::UnitX();
  BoxSpec spec;
  spec.size = Vec3(0.3, 0.3, 0.3);
  spec.world_from_body =
      Pose{ramp.world_from_body.translation + 0.65 * normal - 20.0 * downhill, tilt};
  spec.material = MakeMaterial(mu, 0.0);
  const BodyId box = AddBox(&world, spec);
  const Vec3 start = spec.world_from_body.translation;
  for (int step = 0; step < StepsIn(world, kSeconds); ++step) world.Step();
  const double acceleration = kG * (std::sin(theta) - mu * std::cos(theta));
  const double expected = 0.5 * acceleration * kSeconds * kSeconds;
  EXPECT_NEAR((world.GetPose(box).translation - start).dot(downhill) / expected, 1.0, kRelative);
}

}  // namespace
}  // namespace rigid_body_sim::physics::testing
