// Impacts exact in time: after backing up to the time of impact (Baraff
// 1997, "Rigid Body Simulation II", section 6), the rest of the step is
// simulated, so bounce times, reversals and landings follow the closed form
// to within the touching band, whatever the step size.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "scene.h"

namespace rigid_body_sim::physics::testing {
namespace {

constexpr double kG = 9.81;

// A ball of e = 0.9 dropped from 1 m onto the ground bounces at
// t_0 = sqrt(2 h / g) and then after intervals 2 v_k / g with
// v_k = e^k sqrt(2 g h). Each bounce time is read from the state at the end
// of the step in which the ball turned upwards: in free flight since the
// impact s ago, z - r = v_z s + g s^2 / 2.
std::vector<double> BounceTimes(double hz, int bounces) {
  WorldSettings settings;
  settings.time_step = 1.0 / hz;
  settings.sleep.enabled = false;
  World world(settings);
  AddGround(&world, MakeMaterial(0.5, 0.0));
  SphereSpec spec;
  spec.radius = 0.1;
  spec.world_from_body = Translation(0.0, 0.0, 1.1);
  spec.material = MakeMaterial(0.5, 0.9);
  const BodyId ball = AddSphere(&world, spec);
  std::vector<double> times;
  double previous_vz = 0.0;
  while (static_cast<int>(times.size()) < bounces && world.time() < 10.0) {
    world.Step();
    const double vz = world.GetLinearVelocity(ball).z();
    if (previous_vz < 0.0 && vz > 0.0) {
      const double height = world.GetPose(ball).translation.z() - spec.radius;
      const double since = (-vz + std::sqrt(vz * vz + 2.0 * kG * height)) / kG;
      times.push_back(world.time() - since);
    }
    previous_vz = vz;
  }
  return times;
}

TEST(ImpactTest, BounceTimesFollowTheClosedFormAtAnyStep) {
  constexpr int kBounces = 5;
  std::vector<double> expected;
  double speed = std::sqrt(2.0 * kG * 1.0);
  double time = std::sqrt(2.0 * 1.0 / kG);
  for (int k = 0; k < kBounces; ++k) {
    expected.push_back(time);
    speed *= 0.9;
    time += 2.0 * speed / kG;
  }
  for (const double hz : {240.0, 60.0}) {
    const std::vector<double> times = BounceTimes(hz, kBounces);
    ASSERT_EQ(times.size(), expected.size()) << hz << " Hz";
    for (int k = 0; k < kBounces; ++k) {
      EXPECT_NEAR(times[k], expected[k], 1e-4) << "bounce " << k << " at " << hz << " Hz";
    }
  }
}

// Two elastic boxes closing at 480 m/s meet 0.3 of the way into their
// second step. They reverse within that step: at its end and at every later
// one each box is where the closed form puts it, to within the touching
// band the impact search stops in (1e-5 m).
TEST(ImpactTest, ElasticBoxesReverseWithinTheirImpactStep) {
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  World world(settings);
  constexpr double kSpeed = 240.0;  // m/s, each
  const double impact_time = 1.3 / 240.0;
  const double gap = 2.0 * kSpeed * impact_time;
  BoxSpec left;
  left.size = Vec3::Constant(0.1);
  left.material = MakeMaterial(0.0, 1.0);
  left.world_from_body = Translation(-0.05 - 0.5 * gap, 0.0, 1.0);
  left.linear_velocity = Vec3(kSpeed, 0.0, 0.0);
  BoxSpec right = left;
  right.world_from_body = Translation(0.05 + 0.5 * gap, 0.0, 1.0);
  right.linear_velocity = Vec3(-kSpeed, 0.0, 0.0);
  const BodyId left_box = AddBox(&world, left);
  const BodyId right_box = AddBox(&world, right);
  for (int step = 1; step <= 6; ++step) {
    world.Step();
    const double t = world.time();
    const double travelled =
        t < impact_time ? kSpeed * t : kSpeed * impact_time - kSpeed * (t - impact_time);
    const double x0 = left.world_from_body.translation.x();
    EXPECT_NEAR(world.GetPose(left_box).translation.x(), x0 + travelled, 1e-5) << "step " << step;
    EXPECT_NEAR(world.GetPose(right_box).translation.x(), -x0 - travelled, 1e-5) << "step " << step;
    if (t > impact_time) {
      EXPECT_NEAR(world.GetLinearVelocity(left_box).x(), -kSpeed, 1e-9) << "step " << step;
    }
  }
}

// Cubes of 1 and 2 cm dropped from 3 m tumble on the ground after landing
// on a corner, spinning at hundreds of rad/s, and still come to rest on a
// face within 3 s. A body already touching the ground is never held at the
// start of its step (it would freeze there with its velocity).
TEST(ImpactTest, SmallCubesComeToRestOnAFace) {
  for (const double size : {0.01, 0.02}) {
    World world;
    AddGround(&world, MakeMaterial(0.8, 0.0));
    BoxSpec spec;
    spec.size = Vec3::Constant(size);
    spec.mass = 1000.0 * size * size * size;
    spec.world_from_body = Translation(0.0, 0.0, 3.0);
    spec.world_from_body.rotation = Quat(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
    spec.angular_velocity = Vec3(1.0, -2.0, 0.5);
    spec.material = MakeMaterial(0.5, 0.0);
    const BodyId cube = AddBox(&world, spec);
    int frozen_steps = 0;
    while (world.time() < 3.0 && world.GetBody(cube).awake) {
      const Pose before = world.GetPose(cube);
      world.Step();
      const Pose after = world.GetPose(cube);
      const bool still = after.translation == before.translation &&
                         after.rotation.coeffs() == before.rotation.coeffs();
      const double speed = world.GetLinearVelocity(cube).norm();
      if (still && speed > 1e-3) ++frozen_steps;
    }
    EXPECT_FALSE(world.GetBody(cube).awake) << size << " m";
    EXPECT_EQ(frozen_steps, 0) << size << " m";
    // On a face: the centre half an edge above the ground, less the slop.
    EXPECT_NEAR(world.GetPose(cube).translation.z(), 0.5 * size,
                world.settings().solver.penetration_slop)
        << size << " m";
  }
}

// A box spawned 5 cm into the ground and 10 cm into a resting neighbour:
// FindOverlaps names both with their depths, deepest first, and the step
// pushes them apart by positions only, so no body ever moves faster than
// sqrt(2 g d) + 0.1 m/s (what falling through the depth would give, plus
// a margin), and the box ends at rest on the ground.
TEST(ImpactTest, SpawnedIntoOverlapSeparatesWithoutLaunching) {
  World world;
  const BodyId ground = AddGround(&world, MakeMaterial(0.5, 0.0));
  BoxSpec neighbour_spec;
  neighbour_spec.world_from_body = Translation(1.0, 0.0, 0.5);
  neighbour_spec.material = MakeMaterial(0.5, 0.0);
  const BodyId neighbour = AddBox(&world, neighbour_spec);
  BoxSpec spec;
  spec.world_from_body = Translation(0.1, 0.0, 0.45);
  spec.material = MakeMaterial(0.5, 0.0);
  const BodyId box = AddBox(&world, spec);
  const std::vector<BodyOverlap> overlaps = world.FindOverlaps(box);
  ASSERT_EQ(overlaps.size(), 2u);
  EXPECT_EQ(overlaps[0].other, neighbour);
  EXPECT_NEAR(overlaps[0].depth, 0.1, 1e-9);
  EXPECT_EQ(overlaps[1].other, ground);
  EXPECT_NEAR(overlaps[1].depth, 0.05, 1e-9);
  EXPECT_TRUE(world.FindOverlaps(BodyId{}).empty());
  const double limit = std::sqrt(2.0 * kG * 0.1) + 0.1;
  double fastest = 0.0;
  for (int step = 0; step < 240 * 3; ++step) {
    world.Step();
    for (const BodyId id : {box, neighbour}) {
      fastest = std::max(fastest, world.GetLinearVelocity(id).norm());
    }
  }
  EXPECT_LE(fastest, limit);
  // What is left is the penetration slop the split impulse leaves alone.
  const double slop = world.settings().solver.penetration_slop + 1e-9;
  for (const BodyOverlap& left : world.FindOverlaps(box)) EXPECT_LE(left.depth, slop);
  EXPECT_NEAR(world.GetPose(box).translation.z(), 0.5, slop);
}

}  // namespace
}  // namespace rigid_body_sim::physics::testing
