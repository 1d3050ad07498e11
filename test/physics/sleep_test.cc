// Sleeping islands: their frozen contacts keep reporting the forces that hold
// them, and waking, teleporting or destroying a body updates those reports.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "scene.h"

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

constexpr double kG = 9.81;
constexpr double kMass = 1.0;

BodyId AddUnitBox(World* world, double x, double z) {
  BoxSpec spec;
  spec.mass = kMass;
  spec.world_from_body = Translation(x, 0, z);
  spec.material = MakeMaterial(0.5, 0.0);
  return AddBox(world, spec);
}

// Steps until `body` sleeps (false after `seconds`), then once more so that
// contacts() holds the frozen reports of the sleeping pairs.
bool StepUntilAsleep(World* world, BodyId body, double seconds) {
  const int steps = static_cast<int>(std::lround(seconds / world->settings().time_step));
  for (int step = 0; step < steps; ++step) {
    world->Step();
    if (!world->GetBody(body).awake) {
      world->Step();
      return true;
    }
  }
  return false;
}

bool Names(const ContactReport& report, BodyId body) {
  return report.body_a.index == body.index || report.body_b.index == body.index;
}

std::vector<ContactReport> ReportsNaming(const World& world, BodyId body) {
  std::vector<ContactReport> reports;
  for (const ContactReport& report : world.contacts()) {
    if (Names(report, body)) reports.push_back(report);
  }
  return reports;
}

void ExpectSameReports(const std::vector<ContactReport>& x, const std::vector<ContactReport>& y) {
  ASSERT_EQ(x.size(), y.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_TRUE(x[i].body_a == y[i].body_a && x[i].body_b == y[i].body_b) << i;
    EXPECT_TRUE(x[i].position_world == y[i].position_world) << i;
    EXPECT_EQ(x[i].normal_force, y[i].normal_force) << i;
  }
}

// A box at rest on the ground sleeps, and its frozen contacts still carry
// its weight, sum f_i = m g, unchanged while it sleeps.
TEST(SleepTest, SleepingBoxKeepsReportingItsWeight) {
  World world;
  const BodyId ground = AddGround(&world, MakeMaterial(0.5, 0.0));
  const BodyId box = AddUnitBox(&world, 0, 0.5);
  ASSERT_TRUE(StepUntilAsleep(&world, box, 2.0));
  EXPECT_EQ(world.AwakeBodyCount(), 0u);
  const std::vector<ContactReport> reports = ReportsNaming(world, box);
  EXPECT_GE(reports.size(), 3u);
  EXPECT_NEAR(NormalForceBetween(world, box, ground) / (kMass * kG), 1.0, 0.01);
  const Pose pose = world.GetPose(box);
  for (int step = 0; step < 240; ++step) world.Step();
  EXPECT_EQ(world.AwakeBodyCount(), 0u);
  ExpectSameReports(ReportsNaming(world, box), reports);
  EXPECT_TRUE(world.GetPose(box).translation == pose.translation);
  EXPECT_TRUE(world.GetPose(box).rotation.coeffs() == pose.rotation.coeffs());
}

// A sleeping two-box stack: the bottom box is dropped on and woken, then
// the stack sleeps with the ground carrying 2 m g and the lower box m g.
class SleepingStackTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ground_ = AddGround(&world_, MakeMaterial(0.5, 0.0));
    bottom_ = AddUnitBox(&world_, 0, 0.5);
    ASSERT_TRUE(StepUntilAsleep(&world_, bottom_, 2.0));
    // The top box's bottom face starts 0.05 m above the bottom box's top face.
    top_ = AddUnitBox(&world_, 0, world_.GetPose(bottom_).translation.z() + 1.05);
    ASSERT_EQ(world_.AwakeBodyCount(), 1u);
    int step = 0;
    for (; step < 240 && NormalForceBetween(world_, top_, bottom_) == 0.0; ++step) world_.Step();
    ASSERT_LT(step, 240) << "the top box never reached the bottom one";
    EXPECT_EQ(world_.AwakeBodyCount(), 2u) << "the impact must wake the bottom box";
    ASSERT_TRUE(StepUntilAsleep(&world_, bottom_, 5.0));
    ASSERT_EQ(world_.AwakeBodyCount(), 0u);
  }

  World world_;
  BodyId ground_, bottom_, top_;
};

TEST_F(SleepingStackTest, FrozenStackCarriesBothWeights) {
  EXPECT_NEAR(NormalForceBetween(world_, bottom_, ground_) / (2 * kMass * kG), 1.0, 0.01);
  EXPECT_NEAR(NormalForceBetween(world_, top_, bottom_) / (kMass * kG), 1.0, 0.01);
  EXPECT_EQ(NormalForceBetween(world_, top_, ground_), 0.0);
}

// Teleporting the top box away drops its frozen contacts, and the bottom box
// wakes and settles back to carrying only its own weight, m g.
TEST_F(SleepingStackTest, TeleportedTopBoxLeavesBottomWithItsOwnWeight) {
  ASSERT_TRUE(world_.SetState(top_, Translation(20, 0, 10), Vec3::Zero(), Vec3::Zero()).ok());
  world_.Step();
  EXPECT_TRUE(ReportsNaming(world_, top_).empty());
  EXPECT_TRUE(world_.GetBody(bottom_).awake) << "the bottom box must notice the top one left";
  ASSERT_TRUE(StepUntilAsleep(&world_, bottom_, 3.0));
  EXPECT_NEAR(NormalForceBetween(world_, bottom_, ground_) / (kMass * kG), 1.0, 0.01);
  EXPECT_EQ(NormalForceBetween(world_, top_, bottom_), 0.0);
}

// Destroying one of two sleeping boxes drops its reports and keeps the other
// box's frozen ones, which still carry m g.
TEST(SleepTest, DestroyedSleepingBoxLeavesTheOthersReports) {
  World world;
  const BodyId ground = AddGround(&world, MakeMaterial(0.5, 0.0));
  const BodyId kept = AddUnitBox(&world, 0, 0.5);
  const BodyId destroyed = AddUnitBox(&world, 3, 0.5);
  ASSERT_TRUE(StepUntilAsleep(&world, kept, 2.0));
  ASSERT_EQ(world.AwakeBodyCount(), 0u);
  ASSERT_FALSE(ReportsNaming(world, destroyed).empty());
  const std::vector<ContactReport> kept_reports = ReportsNaming(world, kept);
  ASSERT_TRUE(world.DestroyBody(destroyed).ok());
  world.Step();
  EXPECT_TRUE(ReportsNaming(world, destroyed).empty());
  EXPECT_EQ(world.AwakeBodyCount(), 0u);
  ExpectSameReports(ReportsNaming(world, kept), kept_reports);
  EXPECT_NEAR(NormalForceBetween(world, kept, ground) / (kMass * kG), 1.0, 0.01);
}

// A ball on a 0.5 degree slope rolls without slipping, x = 1/2 (5/7) g
// sin(theta) t^2 (solid sphere, I = 2/5 m r^2). Its radius, 0.5 m, keeps it
// slower than both sleep thresholds (0.05 m/s, 0.1 rad/s) for its first
// 0.84 s. It gains speed at every step, so it is getting under way, not
// settling: it must not fall asleep.
TEST(SleepTest, BallRollingOffAGentleSlopeStaysAwake) {
  const double theta = 0.5 * M_PI / 180.0;
  WorldSettings settings;
  settings.gravity = kG * Vec3(std::sin(theta), 0.0, -std::cos(theta));
  World world(settings);
  AddGround(&world, MakeMaterial(0.5, 0.0));
  SphereSpec spec;
  spec.radius = 0.5;
  spec.world_from_body = Translation(0, 0, spec.radius);
  spec.material = MakeMaterial(0.5, 0.0);
  const BodyId ball = AddSphere(&world, spec);
  const double t = 2.0;
  for (int step = 0; step < static_cast<int>(std::lround(t / settings.time_step)); ++step) {
    world.Step();
  }
  EXPECT_TRUE(world.GetBody(ball).awake);
  const double expected = 0.5 * (5.0 / 7.0) * kG * std::sin(theta) * t * t;
  EXPECT_NEAR(world.GetPose(ball).translation.x() / expected, 1.0, 0.01)
      << "rolled " << world.GetPose(ball).translation.x() << " m, expected " << expected << " m";
}

// A unit box balanced on an edge, 1 mrad past the balance point, tips over:
// the tilt grows as e^(k t) with k^2 = m g d / I_edge = 9.81 (sqrt(2)/2) /
// (2/3) 1/s^2, so it turns slower than the sleep threshold, 0.1 rad/s, for
// its first 1.3 s. Gaining speed at every step, it must not fall asleep on
// its edge, and ends on a face.
TEST(SleepTest, BoxTippingOffItsEdgeDoesNotFallAsleepOnIt) {
  World world;
  AddGround(&world, MakeMaterial(0.5, 0.0));
  BoxSpec spec;
  spec.material = MakeMaterial(0.5, 0.0);
  spec.world_from_body.rotation = Quat(Eigen::AngleAxisd(M_PI / 4 + 1e-3, Vec3::UnitY()));
  // The lowest edge on the ground: half the box's diagonal below its centre.
  double lowest = 0.0;
  for (const double x : {-0.5, 0.5}) {
    for (const double z : {-0.5, 0.5}) {
      lowest = std::min(lowest, (spec.world_from_body.rotation * Vec3(x, 0, z)).z());
    }
  }
  spec.world_from_body.translation = Vec3(0, 0, -lowest);
  const BodyId box = AddBox(&world, spec);
  for (int step = 0; step < 240 * 3; ++step) world.Step();
  EXPECT_NEAR(world.GetPose(box).translation.z(), 0.5, 1e-3);
}

}  // namespace
}  // namespace rigid_body_sim::physics
