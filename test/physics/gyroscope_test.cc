// Gyroscopic motion under contact: a heavy symmetric top on a frictionless
// floor precesses steadily at the closed-form rate.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scene.h"

namespace rigid_body_sim::physics::testing {
namespace {

// A top of m = 1 kg whose centre of mass is l = 0.1 m up its axis from a
// 5 mm ball tip, I_3 = 0.005 and I_1 = 0.0025 kg m^2 about the centre of
// mass, tilted theta = 0.3 rad and spun at omega_3 about its axis, on a
// floor with mu = 0. No horizontal force acts, so the centre of mass stays
// put, and the floor's push m g at the tip, l sin(theta) from it, turns the
// axis. Steady precession at Omega about the vertical needs
// m g l = Omega (I_3 omega_3 - I_1 Omega cos(theta)) (Goldstein, Poole and
// Safko 2002, "Classical Mechanics", 3rd ed., section 5.7, with the centre
// of mass as the fixed point): the slow root is
// Omega = (I_3 w_3 - sqrt((I_3 w_3)^2 - 4 I_1 cos(theta) m g l)) / (2 I_1 cos(theta)).
// Started on it (omega = (w_3 - Omega cos(theta)) e_3 + Omega z), the top
// keeps its tilt and turns its axis at Omega for 3 s.
TEST(GyroscopeTest, TopOnAFrictionlessFloorPrecessesAtTheClosedFormRate) {
  constexpr double kMass = 1.0;
  constexpr double kArm = 0.1;  // m, tip centre to centre of mass
  constexpr double kSpinInertia = 0.005;
  constexpr double kTiltInertia = 0.0025;
  constexpr double kTilt = 0.3;
  constexpr double kTip = 0.005;  // m, radius of the ball tip
  constexpr double kG = 9.81;
  for (const double spin : {100.0, 200.0}) {
    SCOPED_TRACE(spin);
    const double cos_tilt = std::cos(kTilt);
    const double momentum = kSpinInertia * spin;
    const double precession =
        (momentum -
         std::sqrt(momentum * momentum - 4.0 * kTiltInertia * cos_tilt * kMass * kG * kArm)) /
        (2.0 * kTiltInertia * cos_tilt);
    WorldSettings settings;
    settings.sleep.enabled = false;
    World world(settings);
    AddGround(&world, MakeMaterial(0.0, 0.0));
    BodyDef def;
    const Quat tilt(Eigen::AngleAxisd(kTilt, Vec3::UnitY()));
    const Vec3 axis = tilt * Vec3::UnitZ();
    def.world_from_body = Pose{Vec3(0.0, 0.0, kTip), tilt};
    def.mass_properties.mass = kMass;
    def.mass_properties.center_of_mass = Vec3(0.0, 0.0, kArm);
    def.mass_properties.inertia_about_com =
        Vec3(kTiltInertia, kTiltInertia, kSpinInertia).asDiagonal();
    def.angular_velocity = (spin - precession * cos_tilt) * axis + precession * Vec3::UnitZ();
    // The centre of mass at rest: the body origin (the tip) moves with
    // omega x (origin - centre of mass).
    def.linear_velocity = def.angular_velocity.cross(-kArm * axis);
    ShapeDef tip;
    tip.geometry = Sphere{kTip};
    tip.material = MakeMaterial(0.0, 0.0);
    def.shapes.push_back(tip);
    const BodyId top = world.CreateBody(def).value();
    const Vec3 center = world.GetPose(top) * Vec3(0.0, 0.0, kArm);
    double turned = 0.0;
    double previous = 0.0;
    double lowest_tilt = kTilt;
    double highest_tilt = kTilt;
    const int steps = static_cast<int>(3.0 / settings.time_step);
    for (int step = 0; step < steps; ++step) {
      world.Step();
      const Vec3 now = world.GetPose(top).rotation * Vec3::UnitZ();
      const double azimuth = std::atan2(now.y(), now.x());
      turned += std::remainder(azimuth - previous, 2.0 * kPi);
      previous = azimuth;
      lowest_tilt = std::min(lowest_tilt, std::acos(now.z()));
      highest_tilt = std::max(highest_tilt, std::acos(now.z()));
    }
    const double rate = turned / (steps * settings.time_step);
    const Vec3 moved = world.GetPose(top) * Vec3(0.0, 0.0, kArm) - center;
    std::printf("spin %.0f rad/s: precession %.5f rad/s (closed form %.5f), tilt in [%.5f, %.5f]\n",
                spin, rate, precession, lowest_tilt, highest_tilt);
    EXPECT_NEAR(rate, precession, 3e-3 * precession);
    EXPECT_NEAR(lowest_tilt, kTilt, 5e-3);
    EXPECT_NEAR(highest_tilt, kTilt, 5e-3);
    EXPECT_LT(moved.norm(), 1e-3);
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics::testing
