// The sleep window (sleep_window.h): steady motion stays in it exactly as
// long as it is slower than the velocity thresholds, and a box rocking on a
// gently curved surface, faster than the thresholds but going nowhere,
// sleeps after time_to_sleep.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "mesh_fixtures_static.h"
#include "physics/dynamics/sleep_window.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/world.h"
#include "scene.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::BoxSpec;
using testing::Build;
using testing::MakeMaterial;
using testing::Translation;

constexpr double kDt = 1.0 / 240.0;  // s
const SleepSettings kSleep;          // 0.05 m/s, 0.1 rad/s, 0.5 s

// Longest time (s) in the window over `seconds` of a body whose principal
// frame follows `pose_at(t)`.
template <typename PoseAt>
double LongestStay(PoseAt pose_at, double seconds) {
  const SleepWindowLimits limits =
      MakeSleepWindowLimits(kSleep.linear_velocity, kSleep.angular_velocity, kSleep.time_to_sleep);
  SleepWindow window;
  double longest = 0.0;
  for (int k = 0; k <= static_cast<int>(std::lround(seconds / kDt)); ++k) {
    longest = std::max(longest, UpdateSleepWindow(pose_at(k * kDt), limits, kDt, &window));
  }
  return longest;
}

// A point moving at s for a time t sweeps a segment whose sphere has radius
// s t / 2: it stays within r = v T / 2 for T / (s / v) > T when s < v, and
// never for T when s > v. The same holds for a turn at omega < or > omega_max, whose
// off-centre points move at omega d = omega v / omega_max.
TEST(SleepWindowTest, SteadyMotionStaysAsLongAsItIsBelowTheThresholds) {
  const double t = kSleep.time_to_sleep;
  for (const double fraction : {0.95, 1.05}) {
    const double speed = fraction * kSleep.linear_velocity;
    const double sliding =
        LongestStay([speed](double time) { return Translation(speed * time, 0.3, 0.5); }, 3.0 * t);
    const double turn_rate = fraction * kSleep.angular_velocity;
    const double turning = LongestStay(
        [turn_rate](double time) {
          Pose pose = Translation(1.0, 2.0, 0.5);
          pose.rotation = Quat(Eigen::AngleAxisd(turn_rate * time, Vec3(1, 2, 3).normalized()));
          return pose;
        },
        3.0 * t);
    if (fraction < 1.0) {
      EXPECT_GE(sliding, t) << fraction;
      EXPECT_GE(turning, t) << fraction;
    } else {
      EXPECT_LT(sliding, t) << fraction;
      EXPECT_LT(turning, t) << fraction;
    }
  }
}

// An oscillation x = A sin(2 pi t / 0.3 s) of any speed stays in the window
// while its sphere, of radius A, is within r = v T / 2 (12.5 mm), and
// leaves it when A is larger.
TEST(SleepWindowTest, OscillationStaysWhileItsAmplitudeIsWithinTheLimit) {
  const double limit = 0.5 * kSleep.linear_velocity * kSleep.time_to_sleep;
  for (const double fraction : {0.9, 1.1}) {
    const double amplitude = fraction * limit;
    const double stay = LongestStay(
        [amplitude](double time) {
          return Translation(amplitude * std::sin(2.0 * M_PI * time / 0.3), 0.0, 0.5);
        },
        2.0);
    if (fraction < 1.0) {
      EXPECT_GE(stay, 2.0 - kDt);
    } else {
      EXPECT_LT(stay, kSleep.time_to_sleep);
    }
  }
}

// A unit box (1 kg) on the crest of a ridge z = -x^2 / (2 R), R = 18 m, of
// 0.1 m facets, rolls to and fro about the crest: the potential
// m g [(R + h) cos(theta) + R theta sin(theta)] gives omega^2 =
// g (R - h) / (k^2 + h^2) with h = 0.5 m, k^2 = 1/6 m^2, so omega = 20.3
// rad/s. Set rolling at w0, it swings to theta0 = w0 / omega; its off-centre
// point along x moves on a segment of half-length sqrt(2) h theta0. At w0 =
// 0.3 rad/s (theta0 = 0.0148 rad, 10.5 mm, under the 12.5 mm limit) it is
// three times faster than the angular threshold yet sleeps after
// time_to_sleep; at 0.6 rad/s (21 mm) it is still awake then.
struct RockResult {
  bool asleep = false;
  double tilt = 0.0;  // rad, the box's tilt when the run ended
};

RockResult RockOnRidge(double w0, double seconds) {
  const double radius = 18.0;
  World world;
  BodyDef ground;
  ground.is_static = true;
  ShapeDef mesh;
  mesh.geometry = StaticMesh{Build(testing::MakeGrid(
      -1.5, -1.5, 0.1, 30, 30, [radius](double x, double) { return -x * x / (2.0 * radius); }))};
  mesh.material = MakeMaterial(0.5, 0.0);
  ground.shapes.push_back(mesh);
  EXPECT_TRUE(world.CreateBody(ground).ok());
  BoxSpec spec;
  spec.size = Vec3::Ones();
  spec.world_from_body = Translation(0.0, 0.0, 0.5);
  spec.material = MakeMaterial(0.5, 0.0);
  const BodyId box = AddBox(&world, spec);
  // Rolling about the contact point below the centre: v = w x (0, 0, h).
  EXPECT_TRUE(
      world.SetState(box, spec.world_from_body, Vec3(0.5 * w0, 0.0, 0.0), Vec3(0.0, w0, 0.0)).ok());
  RockResult result;
  const int steps = static_cast<int>(std::lround(seconds / world.settings().time_step));
  for (int step = 0; step < steps && !result.asleep; ++step) {
    world.Step();
    result.asleep = !world.GetBody(box).awake;
  }
  const Vec3 up = world.GetBody(box).WorldFromBody().rotation * Vec3::UnitZ();
  result.tilt = std::acos(std::min(1.0, up.z()));
  return result;
}

TEST(SleepWindowTest, BoxRockingOnARidgeSleepsWhenItGoesNowhere) {
  const double omega = std::sqrt(9.81 * (18.0 - 0.5) / (1.0 / 6.0 + 0.25));
  const double slow_rock = 0.3;
  const RockResult small = RockOnRidge(slow_rock, kSleep.time_to_sleep + 0.05);
  EXPECT_TRUE(small.asleep);
  EXPECT_LE(small.tilt, slow_rock / omega + 1e-3);
  const RockResult large = RockOnRidge(2.0 * slow_rock, kSleep.time_to_sleep + 0.05);
  EXPECT_FALSE(large.asleep);
}

}  // namespace
}  // namespace rigid_body_sim::physics
