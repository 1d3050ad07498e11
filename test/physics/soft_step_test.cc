// The soft step (MotionSolverKind::kSoftStep) against closed-form answers:
// rest on the ground, the bounce apex e^2 h, the slide down an incline, a
// bullet stopped by a thin wall, the weight carried, a pyramid that stands;
// its graph colouring against a brute-force check (its threads are
// threads_test's).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "physics/scene.h"
#include "physics/solver/constraint_colouring.h"
#include "physics/solver/support_balance.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::AddGround;
using testing::AddSphere;
using testing::BoxSpec;
using testing::MakeMaterial;
using testing::NormalForceBetween;
using testing::SphereSpec;
using testing::Translation;

WorldSettings SoftSettings(int threads = 1) {
  WorldSettings settings;
  settings.motion_solver = MotionSolverKind::kSoftStep;
  settings.threads = threads;
  return settings;
}

// A 0.2 m box of `mass` resting on the ground z = 0, its centre at 0.1 m.
BoxSpec RestingBox(double mass = 1.0) {
  BoxSpec spec;
  spec.size = Vec3(0.2, 0.2, 0.2);
  spec.mass = mass;
  spec.world_from_body = Translation(0.0, 0.0, 0.1);
  return spec;
}

// A pyramid of unit boxes (mu = 0.6, e = 0) on the ground, spawned
// touching: row r has `rows` - r boxes, each on two of the row below.
// Returns the top box.
BodyId AddPyramid(World* world, int rows) {
  AddGround(world, MakeMaterial(0.6, 0.0));
  BodyId top;
  for (int row = 0; row < rows; ++row) {
    for (int i = 0; i < rows - row; ++i) {
      BoxSpec spec;
      spec.material = MakeMaterial(0.6, 0.0);
      spec.world_from_body = Translation(i - 0.5 * (rows - row - 1), 0.0, 0.5 + row);
      top = AddBox(world, spec);
    }
  }
  return top;
}

// The fidelity tests, with wide blocks (the default for these small
// scenes) and with compact ones, whose rows keep what the sub-steps only
// read in floats (SoftStepSettings::compact_blocks_from = 0).
class SoftStepFidelityTest : public ::testing::TestWithParam<bool> {
 protected:
  WorldSettings Settings() const {
    WorldSettings settings = SoftSettings();
    if (GetParam()) settings.soft_step.compact_blocks_from = 0;
    return settings;
  }
};

INSTANTIATE_TEST_SUITE_P(Blocks, SoftStepFidelityTest, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? "Compact" : "Wide";
                         });

void StepFor(World* world, double seconds) {
  const int steps = static_cast<int>(std::lround(seconds / world->settings().time_step));
  for (int i = 0; i < steps; ++i) world->Step();
}

TEST_P(SoftStepFidelityTest, BoxRestsOnTheGroundCarryingItsWeight) {
  World world(Settings());
  const BodyId ground = AddGround(&world, MakeMaterial(0.5, 0.0));
  const BoxSpec spec = RestingBox(2.0);
  const BodyId box = AddBox(&world, spec);
  // 0.3 s: settled, and still awake (sleep needs 0.5 s of rest).
  StepFor(&world, 0.3);
  const double weight = spec.mass * 9.81;
  std::printf("normal force %.5f N, m g = %.5f N\n", NormalForceBetween(world, box, ground),
              weight);
  EXPECT_NEAR(NormalForceBetween(world, box, ground), weight, 0.01 * weight);
  StepFor(&world, 1.7);
  const Body& body = world.GetBody(box);
  std::printf("box at rest at %.7f m, 0.1 m\n", body.position.z());
  EXPECT_NEAR(body.position.z(), 0.1, 1e-3);
  EXPECT_LT(body.linear_velocity.norm(), 1e-3);
  EXPECT_LT(body.angular_velocity.norm(), 1e-3);
}

// A ball of e = 0.5 dropped from h rises to e^2 h: Newton's law on the
// speed it hits at, sqrt(2 g h).
TEST_P(SoftStepFidelityTest, BounceApexIsRestitutionSquaredTimesTheDrop) {
  World world(Settings());
  AddGround(&world, MakeMaterial(0.5, 0.5));
  SphereSpec spec;
  spec.radius = 0.1;
  spec.material = MakeMaterial(0.5, 0.5);
  const double drop = 1.0;
  spec.world_from_body = Translation(0.0, 0.0, spec.radius + drop);
  const BodyId ball = AddSphere(&world, spec);
  double apex = 0.0;
  bool bounced = false;
  for (int i = 0; i < 240; ++i) {
    world.Step();
    const Body& body = world.GetBody(ball);
    if (body.linear_velocity.z() > 0.0) bounced = true;
    if (bounced) apex = std::max(apex, body.position.z() - spec.radius);
  }
  ASSERT_TRUE(bounced);
  std::printf("bounce apex %.5f m, e^2 h = %.5f m\n", apex, 0.25 * drop);
  EXPECT_NEAR(apex, 0.25 * drop, 0.02 * 0.25 * drop);
}

// The landing is reported once, as a colliding contact, at the speed the
// ball fell to: sqrt(2 g h), within 2 g h_s for sub-steps of h_s (the
// sub-step it closes in is one; symplectic Euler's lead over the parabola,
// g h_s t / 2 in height at t = 0.45 s, is under another).
TEST_P(SoftStepFidelityTest, ImpactIsReportedAsCollidingAtItsSpeed) {
  World world(Settings());
  const BodyId ground = AddGround(&world, MakeMaterial(0.5, 0.0));
  SphereSpec spec;
  spec.radius = 0.1;
  spec.material = MakeMaterial(0.5, 0.0);
  const double drop = 1.0;
  spec.world_from_body = Translation(0.0, 0.0, spec.radius + drop);
  const BodyId ball = AddSphere(&world, spec);
  std::vector<ContactReport> impacts;
  for (int i = 0; i < 240; ++i) {
    world.Step();
    for (const ContactReport& report : world.contacts()) {
      if (report.type == ContactType::kColliding) impacts.push_back(report);
    }
  }
  ASSERT_EQ(impacts.size(), 1u);
  const ContactReport& impact = impacts[0];
  EXPECT_TRUE((impact.body_a == ball && impact.body_b == ground) ||
              (impact.body_a == ground && impact.body_b == ball));
  const double speed = std::sqrt(2.0 * 9.81 * drop);
  const WorldSettings& settings = world.settings();
  const double sub_step = settings.time_step / settings.soft_step.substeps;
  std::printf("impact at %.5f m/s, sqrt(2 g h) = %.5f m/s\n", -impact.normal_velocity, speed);
  EXPECT_NEAR(-impact.normal_velocity, speed, 2.0 * 9.81 * sub_step);
  // Inelastic: the ball rests where it landed.
  EXPECT_LT(world.GetBody(ball).linear_velocity.norm(), 1e-6);
  EXPECT_NEAR(world.GetBody(ball).position.z(), spec.radius, 1e-4);
}

// A box on a 28 degree incline with mu = 0.5 slides a = g (sin t - mu cos t)
// from rest: a t^2 / 2 after t.
TEST_P(SoftStepFidelityTest, BoxSlidesDownAnInclineAsCoulombSays) {
  World world(Settings());
  const double angle = 28.0 * M_PI / 180.0;
  Pose world_from_ground;
  world_from_ground.rotation = Quat(Eigen::AngleAxisd(angle, Vec3::UnitY()));
  AddGround(&world, MakeMaterial(0.5, 0.0), world_from_ground);
  BoxSpec spec;
  spec.size = Vec3(0.2, 0.2, 0.2);
  spec.material = MakeMaterial(0.5, 0.0);
  spec.world_from_body.rotation = world_from_ground.rotation;
  spec.world_from_body.translation = world_from_ground.rotation * Vec3(0.0, 0.0, 0.1);
  const BodyId box = AddBox(&world, spec);
  const Vec3 start = world.GetBody(box).position;
  const double seconds = 2.0;
  StepFor(&world, seconds);
  const Vec3 downhill = world_from_ground.rotation * Vec3::UnitX();
  const double slide = (world.GetBody(box).position - start).dot(downhill);
  const double expected =
      0.5 * 9.81 * (std::sin(angle) - 0.5 * std::cos(angle)) * seconds * seconds;
  std::printf("incline slide %.5f m, closed form %.5f m\n", std::abs(slide), expected);
  // Downhill is +x of the tilted ground, which faces down the slope.
  EXPECT_NEAR(std::abs(slide), expected, 0.02 * expected);
}

// A 1 cm cube at 100 m/s, 42 cm a step, meets a 1 cm wall: the speculative
// contact stops it at the wall instead of past it.
TEST_P(SoftStepFidelityTest, BulletDoesNotPassAThinWall) {
  WorldSettings settings = Settings();
  settings.gravity = Vec3::Zero();
  World world(settings);
  BoxSpec wall;
  wall.size = Vec3(0.01, 1.0, 1.0);
  wall.is_static = true;
  wall.world_from_body = Translation(1.0, 0.0, 0.0);
  AddBox(&world, wall);
  BoxSpec bullet;
  bullet.size = Vec3(0.01, 0.01, 0.01);
  bullet.mass = 0.01;
  bullet.linear_velocity = Vec3(100.0, 0.0, 0.0);
  const BodyId id = AddBox(&world, bullet);
  StepFor(&world, 0.1);
  // The wall's near face is at 0.995, the bullet's centre 5 mm before it.
  std::printf("bullet centre at %.5f m, wall face at 0.995 m\n", world.GetBody(id).position.x());
  EXPECT_LT(world.GetBody(id).position.x(), 0.99 + 1e-3);
}

// A pyramid of unit boxes, as the benchmark's: its top box stays within
// 1 mm of where it was spawned.
TEST_P(SoftStepFidelityTest, PyramidStands) {
  World world(Settings());
  constexpr int kRows = 10;
  const BodyId top = AddPyramid(&world, kRows);
  const Vec3 start = world.GetBody(top).position;
  StepFor(&world, 3.0);
  const double drift = (world.GetBody(top).position - start).norm();
  std::printf("pyramid of %d rows: top drift %.6f m\n", kRows, drift);
  EXPECT_LT(drift, 1e-3);
}

// A pyramid spawned touching, kept awake: each box rests on two, and the
// end boxes of each row carry one box above on one half, so their loads
// sit off their centres. Seeded with equal loads per point, a box tilted
// on its springs until they balanced that moment: the top of 10 rows sank
// 0.11 mm in 0.3 s (pyramid_40 0.84 mm, pyramid_90 3 mm). Seeded with
// loads balanced in moment, nothing moves.
TEST_P(SoftStepFidelityTest, PyramidSpawnedTouchingHoldsItsTopWhileAwake) {
  WorldSettings settings = Settings();
  settings.sleep.time_to_sleep = 100.0;
  World world(settings);
  constexpr int kRows = 10;
  const BodyId top = AddPyramid(&world, kRows);
  const Vec3 start = world.GetBody(top).position;
  double largest = 0.0;
  for (int k = 0; k < 8; ++k) {
    StepFor(&world, 0.25);
    ASSERT_TRUE(world.GetBody(top).awake);
    largest = std::max(largest, (world.GetBody(top).position - start).norm());
  }
  std::printf("pyramid of %d rows, awake 2 s: top moved at most %.3g m\n", kRows, largest);
  EXPECT_LT(largest, 1e-6);
}

// A 1 kg box whose support on a 2 kg box is offset: the points' loads are
// those of a rigid body on equal springs, lambda_i = L/N + L e.d_i / sum d^2
// along x, so each body's supports carry its load with no moment about it.
TEST(SoftStepTest, NewSupportsCarryTheirLoadWithNoMoment) {
  std::vector<Body> bodies(3);
  bodies[0].is_static = true;
  bodies[1].mass = 2.0;
  bodies[1].position = Vec3(0.0, 0.0, 0.1);
  bodies[2].mass = 1.0;
  bodies[2].position = Vec3(0.05, 0.0, 0.3);
  // Manifold 0: the lower box on the ground, its corners x, y = +-0.1.
  // Manifold 1: the upper box on the lower one, over x in [-0.05, 0.1].
  std::vector<SolverManifold> manifolds(2);
  const std::array<double, 4> xs0 = {-0.1, 0.1, 0.1, -0.1};
  const std::array<double, 4> xs1 = {-0.05, 0.1, 0.1, -0.05};
  const std::array<double, 4> ys = {-0.1, -0.1, 0.1, 0.1};
  for (int m = 0; m < 2; ++m) {
    manifolds[m].body_a = m == 0 ? 1 : 2;
    manifolds[m].body_b = m == 0 ? 0 : 1;
    manifolds[m].point_count = 4;
    manifolds[m].new_pair = true;  // both supports are new
    for (int i = 0; i < 4; ++i) {
      const Vec3 at((m == 0 ? xs0 : xs1)[i], ys[i], m == 0 ? 0.0 : 0.2);
      manifolds[m].points[i].r_a = at - bodies[manifolds[m].body_a].position;
      manifolds[m].points[i].normal_impulse = 1.0;  // replaced
    }
  }
  SupportBalanceInput input;
  input.bodies = &bodies;
  input.gravity = Vec3(0.0, 0.0, -9.81);
  input.dt = 0.01;
  input.contact_tolerance = 1e-4;
  BalanceNewSupports(input, UprightSupportsHighestFirst(input, manifolds), &manifolds);
  const double unit = 9.81 * 0.01;  // N s, 1 kg's weight over the step
  // Upper box: L = 1, points at x - 0.025 = -+0.075, e = 0.025.
  // Lower box: L = 3, load centre (0.1 * 2/3 - 0.05 * 1/3) / 3 = 1/60,
  // points at x = +-0.1.
  for (int i = 0; i < 4; ++i) {
    const double d1 = xs1[i] - 0.025;
    EXPECT_NEAR(manifolds[1].points[i].normal_impulse,
                unit * (0.25 + 0.025 * d1 / (4 * 0.075 * 0.075)), 1e-12);
    EXPECT_NEAR(manifolds[0].points[i].normal_impulse,
                unit * (0.75 + 3.0 / 60.0 * xs0[i] / (4 * 0.01)), 1e-12);
  }
}

// An island asleep is left alone: its pose does not change by a bit, and
// its contacts are still reported, with the weight they carry.
TEST(SoftStepTest, SleepingBoxIsUntouchedAndStillReported) {
  World world(SoftSettings());
  const BodyId ground = AddGround(&world, MakeMaterial(0.5, 0.0));
  const BodyId box = AddBox(&world, RestingBox());
  StepFor(&world, 1.5);
  ASSERT_EQ(world.AwakeBodyCount(), 0u);
  const Body asleep = world.GetBody(box);
  StepFor(&world, 1.0);
  const Body& later = world.GetBody(box);
  EXPECT_EQ(later.position, asleep.position);
  EXPECT_EQ(later.orientation.coeffs(), asleep.orientation.coeffs());
  EXPECT_NEAR(NormalForceBetween(world, box, ground), 9.81, 0.01 * 9.81);
}

// The cache keeps a step's impulses in the same units for both solvers, so
// switching at run time leaves a resting box at rest.
TEST(SoftStepTest, SwitchingSolversLeavesARestingBoxAtRest) {
  WorldSettings settings;
  settings.sleep.enabled = false;
  World world(settings);
  AddGround(&world, MakeMaterial(0.5, 0.0));
  const BodyId box = AddBox(&world, RestingBox());
  for (const MotionSolverKind solver :
       {MotionSolverKind::kExact, MotionSolverKind::kSoftStep, MotionSolverKind::kExact}) {
    settings.motion_solver = solver;
    ASSERT_TRUE(world.SetSettings(settings).ok());
    StepFor(&world, 0.5);
    const Body& body = world.GetBody(box);
    EXPECT_NEAR(body.position.z(), 0.1, 1e-4);
    EXPECT_LT(body.linear_velocity.norm(), 1e-4);
  }
}

// No colour holds two constraints with a moving body in common, and every
// constraint is coloured once or overflows.
TEST(SoftStepTest, ColouringSeparatesEveryMovingBody) {
  std::mt19937 random(7);
  constexpr std::uint32_t kBodies = 200;
  std::vector<std::uint8_t> moving(kBodies);
  for (std::uint32_t b = 0; b < kBodies; ++b) moving[b] = b % 7 != 0;
  std::vector<std::uint32_t> body_a;
  std::vector<std::uint32_t> body_b;
  std::uniform_int_distribution<std::uint32_t> pick(0, kBodies - 1);
  for (int i = 0; i < 3000; ++i) {
    body_a.push_back(pick(random));
    body_b.push_back(i % 5 == 0 ? 0u : pick(random));  // body 0, static, is in many
  }
  std::vector<std::uint32_t> used;
  std::vector<std::uint8_t> colour_of;
  ConstraintColouring colouring;
  ColourConstraints(body_a, body_b, moving, &used, &colour_of, &colouring);
  ASSERT_EQ(colouring.order.size(), body_a.size());
  std::vector<int> seen(body_a.size(), 0);
  for (const std::uint32_t c : colouring.order) ++seen[c];
  for (const int count : seen) EXPECT_EQ(count, 1);
  for (int colour = 0; colour < colouring.colour_count(); ++colour) {
    std::vector<int> uses(kBodies, 0);
    for (std::uint32_t k = colouring.colour_start[colour]; k < colouring.colour_start[colour + 1];
         ++k) {
      const std::uint32_t c = colouring.order[k];
      if (moving[body_a[c]]) ++uses[body_a[c]];
      if (moving[body_b[c]] && body_b[c] != body_a[c]) ++uses[body_b[c]];
    }
    for (std::uint32_t b = 0; b < kBodies; ++b) EXPECT_LE(uses[b], 1) << "colour " << colour;
  }
}

TEST(SoftStepTest, BadSettingsAreRefusedWithTheirName) {
  World world(SoftSettings());
  WorldSettings settings = SoftSettings();
  settings.soft_step.substeps = 0;
  const Status status = world.SetSettings(settings);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("soft_step.substeps 0"), std::string::npos) << status.message();
  EXPECT_EQ(world.settings().soft_step.substeps, 4);
  settings = SoftSettings();
  settings.soft_step.contact_hertz = std::nan("");
  EXPECT_FALSE(world.SetSettings(settings).ok());
  settings = SoftSettings();
  settings.soft_step.compact_blocks_from = -1;
  const Status compact = world.SetSettings(settings);
  ASSERT_FALSE(compact.ok());
  EXPECT_NE(compact.message().find("soft_step.compact_blocks_from -1 must be >= 0"),
            std::string::npos)
      << compact.message();
}

}  // namespace
}  // namespace rigid_body_sim::physics
