// Free flight: analytic ballistics and torque-free tumbling.
#include <cmath>

#include <gtest/gtest.h>

#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::physics {
namespace {

BodyDef BoxBody(const Vec3& size, double density) {
  BodyDef def;
  def.mass_properties = BoxMassProperties(density, size);
  return def;
}

// The drift x += dt v(t+dt) - dt^2/2 g equals x + dt v(t) + dt^2/2 g, which is
// exact for uniform gravity; only rounding remains (~1e-15 per step).
TEST(FreeFlightTest, FreeFallMatchesParabolaAtDefaultTimeStep) {
  World world;
  const double g = 9.81;
  const double z0 = 10.0;
  BodyDef def = BoxBody(Vec3(1, 1, 1), 1000.0);
  def.world_from_body.translation = Vec3(0, 0, z0);
  const BodyId id = world.CreateBody(def).value();
  const int steps = static_cast<int>(std::lround(1.0 / world.settings().time_step));
  for (int i = 0; i < steps; ++i) world.Step();
  const double t = world.time();
  EXPECT_NEAR(t, 1.0, 1e-12);
  const double kSchemeErrorBound = 1e-9;  // m: exact scheme, rounding only
  EXPECT_NEAR(world.GetPose(id).translation.z(), z0 - 0.5 * g * t * t, kSchemeErrorBound);
  EXPECT_NEAR(world.GetLinearVelocity(id).z(), -g * t, kSchemeErrorBound);
  EXPECT_NEAR(world.GetPose(id).translation.x(), 0.0, 1e-15);
}

TEST(FreeFlightTest, ProjectileWithOffsetCentreOfMassFollowsParabola) {
  WorldSettings settings;
  settings.time_step = 1e-3;
  World world(settings);
  BodyDef def;
  def.mass_properties = BoxMassProperties(500.0, Vec3(0.2, 0.4, 0.6));
  // The body frame origin is 0.3 m from the centre of mass; with no spin its
  // origin moves on the same parabola.
  def.mass_properties.center_of_mass = Vec3(0.3, 0.0, 0.0);
  def.world_from_body.translation = Vec3(1.0, 2.0, 3.0);
  const Vec3 v0(4.0, -1.0, 7.0);
  def.linear_velocity = v0;
  const BodyId id = world.CreateBody(def).value();
  for (int i = 0; i < 1500; ++i) world.Step();
  const double t = world.time();
  const Vec3 expected = Vec3(1.0, 2.0, 3.0) + v0 * t + 0.5 * settings.gravity * t * t;
  EXPECT_LT((world.GetPose(id).translation - expected).norm(), 1e-9);
  EXPECT_LT((world.GetLinearVelocity(id) - (v0 + settings.gravity * t)).norm(), 1e-9);
}

TEST(FreeFlightTest, ConstantForceAtCentreOfMassGivesUniformAcceleration) {
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  World world(settings);
  BodyDef def = BoxBody(Vec3(1, 1, 1), 2.0);  // 2 kg
  const BodyId id = world.CreateBody(def).value();
  const int steps = 240;
  for (int i = 0; i < steps; ++i) {
    ASSERT_TRUE(world.ApplyForceAtPoint(id, Vec3(10.0, 0, 0), Vec3::Zero()).ok());
    world.Step();
  }
  // a = F / m = 5 m/s^2 for 1 s.
  EXPECT_NEAR(world.GetLinearVelocity(id).x(), 5.0, 1e-12);
  EXPECT_NEAR(world.GetPose(id).translation.x(), 2.5, 1e-12);
  EXPECT_LT(world.GetAngularVelocity(id).norm(), 1e-15);
}

// Torque-free rotation near the intermediate principal axis (Dzhanibekov
// effect). For moments I1 > I2 > I3 a spin about axis 2 is unstable with
// growth rate lambda = w sqrt((I1 - I2)(I2 - I3) / (I1 I3)).
TEST(FreeFlightTest, TorqueFreeTumblingConservesMomentumAndFlipsIntermediateAxis) {
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  settings.time_step = 1e-3;
  World world(settings);
  const Vec3 size(1.0, 2.0, 3.0);
  const MassProperties mass_properties = BoxMassProperties(1.0, size);
  BodyDef def;
  def.mass_properties = mass_properties;
  const double spin = 5.0;  // rad/s about the body y axis (intermediate moment)
  def.angular_velocity = Vec3(0.05, spin, 0.05);
  const BodyId id = world.CreateBody(def).value();

  const Mat3 inertia_body = mass_properties.inertia_about_com;
  auto angular_momentum = [&]() {
    const Mat3 rotation = world.GetPose(id).rotation.toRotationMatrix();
    return Vec3(rotation * inertia_body * rotation.transpose() * world.GetAngularVelocity(id));
  };
  auto kinetic_energy = [&]() {
    return 0.5 * world.GetAngularVelocity(id).dot(angular_momentum());
  };
  const Vec3 initial_momentum = angular_momentum();
  const double initial_energy = kinetic_energy();

  int reversals = 0;
  int sign = 1;
  double max_momentum_error = 0.0;
  double max_energy_drift = 0.0;
  for (int i = 0; i < 20000; ++i) {
    world.Step();
    max_momentum_error =
        std::max(max_momentum_error, (angular_momentum() - initial_momentum).norm());
    max_energy_drift = std::max(max_energy_drift, std::abs(kinetic_energy() - initial_energy));
    const Vec3 omega_body = world.GetPose(id).rotation.conjugate() * world.GetAngularVelocity(id);
    // Hysteresis of half the spin, so wobble about zero is not counted.
    if (sign > 0 && omega_body.y() < -0.5 * spin) {
      sign = -1;
      ++reversals;
    } else if (sign < 0 && omega_body.y() > 0.5 * spin) {
      sign = 1;
      ++reversals;
    }
  }
  EXPECT_LT(max_momentum_error / initial_momentum.norm(), 1e-9);
  EXPECT_LT(max_energy_drift / initial_energy, 0.005);
  EXPECT_GE(reversals, 2);
}

// A cube's inertia is isotropic, so its angular velocity is constant in
// torque-free flight and its orientation after t is exp(1/2 omega t) q0: a
// rotation by |omega| t about omega. RK4 ends 1.2e-10 rad off here.
TEST(FreeFlightTest, SpinningCubeTurnsByOmegaTimesTimeAboutOmega) {
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  World world(settings);
  BodyDef def = BoxBody(Vec3::Ones(), 1.0);
  def.world_from_body.rotation = Quat(Eigen::AngleAxisd(0.3, Vec3(1.0, -1.0, 2.0).normalized()));
  const Vec3 omega(1.0, 2.0, 3.0);  // rad/s, world
  def.angular_velocity = omega;
  const BodyId id = world.CreateBody(def).value();
  const int steps = 240;
  for (int i = 0; i < steps; ++i) world.Step();

  const double t = steps * settings.time_step;
  const Quat expected =
      Quat(Eigen::AngleAxisd(omega.norm() * t, omega.normalized())) * def.world_from_body.rotation;
  EXPECT_LT(world.GetPose(id).rotation.angularDistance(expected), 1e-12);
  EXPECT_LT((world.GetAngularVelocity(id) - omega).norm(), 1e-12);
  EXPECT_LT(world.GetPose(id).translation.norm(), 1e-15);
}

// A spin faster than max_turn_per_step / dt is scaled down to it, about the
// same axis, before the drift; the cube (all moments equal) then turns by
// exactly max_turn each step. A spin just below the cap is left alone.
TEST(FreeFlightTest, SpinBeyondAQuarterTurnPerStepIsCappedAboutItsAxis) {
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  World world(settings);
  const double max_speed = settings.max_turn_per_step / settings.time_step;  // rad/s
  const Vec3 axis = Vec3(1.0, -2.0, 0.5).normalized();
  BodyDef fast = BoxBody(Vec3::Constant(0.04), 1500.0);
  fast.angular_velocity = 1e5 * axis;
  const BodyId fast_id = world.CreateBody(fast).value();
  BodyDef slow = BoxBody(Vec3::Constant(0.04), 1500.0);
  slow.world_from_body.translation = Vec3(1.0, 0.0, 0.0);
  slow.angular_velocity = 0.999 * max_speed * axis;
  const BodyId slow_id = world.CreateBody(slow).value();
  world.Step();

  EXPECT_NEAR(world.GetAngularVelocity(fast_id).norm(), max_speed, 1e-9 * max_speed);
  EXPECT_LT(world.GetAngularVelocity(fast_id).normalized().cross(axis).norm(), 1e-12);
  const Quat turned(Eigen::AngleAxisd(settings.max_turn_per_step, axis));
  EXPECT_LT(world.GetPose(fast_id).rotation.angularDistance(turned), 1e-9);
  EXPECT_LT((world.GetAngularVelocity(slow_id) - slow.angular_velocity).norm(), 1e-9);
}

TEST(FreeFlightTest, MaxTurnPerStepOutsideItsRangeIsRefused) {
  for (const double turn : {0.0, -1.0, 3.2, std::nan("")}) {
    WorldSettings settings;
    settings.max_turn_per_step = turn;
    const Status status = ValidateWorldSettings(settings);
    EXPECT_FALSE(status.ok()) << turn;
    EXPECT_NE(status.message().find("max_turn_per_step"), std::string::npos) << status.message();
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics
