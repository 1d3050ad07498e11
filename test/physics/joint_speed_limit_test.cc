// A joint's URDF speed limit bounds what its actuator drives, not its
// passive motion (Gazebo's Joint::CheckAndTruncateForce): a limp pendulum
// swings through it keeping its energy, a velocity motor is held to it, and
// an effort is cut once the joint is past it.
#include <cmath>

#include <gtest/gtest.h>

#include "articulation_fixtures.h"
#include "scene.h"

namespace rigid_body_sim::physics::testing {
namespace {

constexpr double kSpeedLimit = 0.5;  // rad/s

ArticulationDef Pendulum(double start_angle) {
  ArticulationDef def;
  def.fixed_base = true;
  def.links = {Anchor(), Rod(1.0, 1.0)};
  def.joints = {Hinge(1, 0.0, start_angle)};
  def.joints[0].velocity_limit = kSpeedLimit;
  return def;
}

// Released horizontal, the bob passes the bottom at omega = sqrt(2 g / l)
// (4.43 rad/s, nine times the limit; the rod's 1e-4 kg m^2 about its centre
// lowers it by 5e-5).
TEST(JointSpeedLimitTest, LimpPendulumSwingsThroughItsSpeedLimit) {
  World world = MakeWorld();
  const ArticulationId id = world.CreateArticulation(Pendulum(kPi / 2)).value();
  const double inertia = 1e-4 + 1.0;
  const double expected = std::sqrt(2.0 * kG * 1.0 / inertia);
  double fastest = 0.0;
  for (int step = 0; step < 240; ++step) {
    world.Step();
    fastest = std::max(fastest, std::abs(world.GetJointStates(id)[0].velocity));
  }
  // The bottom falls between steps: the fastest step is within the change
  // of speed over one step near it, g dt^2 / 2 / l, of the bottom speed.
  EXPECT_NEAR(fastest, expected, 1e-3);
}

// Without gravity a velocity motor asking 2 rad/s turns the joint at the
// limit; an effort of 1 N m is applied until the joint passes the limit,
// then cut: its speed stops within one step's gain, tau dt / I, above it.
TEST(JointSpeedLimitTest, MotorsAndEffortsStopAtTheSpeedLimit) {
  for (const JointCommandMode mode : {JointCommandMode::kVelocity, JointCommandMode::kEffort}) {
    SCOPED_TRACE(static_cast<int>(mode));
    WorldSettings settings;
    settings.time_step = kDt;
    settings.gravity = Vec3::Zero();
    World world(settings);
    const ArticulationId id = world.CreateArticulation(Pendulum(0.0)).value();
    JointCommand command;
    command.mode = mode;
    command.velocity = 2.0;
    command.effort = 1.0;
    ASSERT_TRUE(world.SetJointCommand(id, 0, command).ok());
    for (int step = 0; step < 480; ++step) world.Step();
    const double speed = world.GetJointStates(id)[0].velocity;
    if (mode == JointCommandMode::kVelocity) {
      EXPECT_NEAR(speed, kSpeedLimit, 1e-9);
    } else {
      const double inertia = 1e-4 + 1.0;
      EXPECT_GT(speed, kSpeedLimit);
      EXPECT_LE(speed, kSpeedLimit + command.effort * kDt / inertia + 1e-12);
    }
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics::testing
