// Contact reports are written when they are first read (World::contacts()),
// not in the step: what is read must be what reading right after the step
// gives, however late it is read and whatever call came between, and the
// collision log must hold every step's collisions either way. The reference
// is a twin world that reads every report as soon as its step ends.
#include <cmath>
#include <functional>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "scene.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::AddGround;
using testing::BoxSpec;
using testing::MakeMaterial;
using testing::Translation;

void ExpectSameReports(const std::vector<ContactReport>& actual,
                       const std::vector<ContactReport>& expected, int step) {
  ASSERT_EQ(actual.size(), expected.size()) << "step " << step;
  for (std::size_t i = 0; i < actual.size(); ++i) {
    const ContactReport& x = actual[i];
    const ContactReport& y = expected[i];
    EXPECT_TRUE(x.body_a == y.body_a && x.body_b == y.body_b) << "step " << step << ", " << i;
    EXPECT_EQ(x.shape_a, y.shape_a);
    EXPECT_EQ(x.shape_b, y.shape_b);
    EXPECT_TRUE(x.position_world == y.position_world) << "step " << step << ", " << i;
    EXPECT_TRUE(x.normal_world == y.normal_world) << "step " << step << ", " << i;
    EXPECT_EQ(x.depth, y.depth);
    EXPECT_EQ(x.normal_velocity, y.normal_velocity);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(x.normal_impulse, y.normal_impulse);
    EXPECT_TRUE(x.friction_impulse_world == y.friction_impulse_world);
    EXPECT_EQ(x.normal_force, y.normal_force);
  }
}

// Three boxes dropped onto a fourth on the ground, one tipped: they collide
// (e = 0.5) and settle, so the steps hold colliding and resting reports.
std::vector<BodyId> DropBoxes(World* world) {
  AddGround(world, MakeMaterial(0.6, 0.5));
  std::vector<BodyId> boxes;
  BoxSpec spec;
  spec.material = MakeMaterial(0.6, 0.5);
  for (int k = 0; k < 4; ++k) {
    spec.world_from_body = Translation(0.1 * k, 0.05 * k, 0.5 + 1.3 * k);
    if (k == 2) spec.world_from_body.rotation = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitX()));
    boxes.push_back(AddBox(world, spec));
  }
  return boxes;
}

// Sleep off: a sleeping pair's reports are written when it falls asleep,
// and only the awake pairs' wait to be read.
WorldSettings SettingsFor(MotionSolverKind solver) {
  WorldSettings settings;
  settings.motion_solver = solver;
  settings.sleep.enabled = false;
  return settings;
}

class ContactReportsTest : public ::testing::TestWithParam<MotionSolverKind> {};

// Read every fifth step, the reports are the reference's of that step; the
// log, taken once at the end, holds the reference's collisions of every
// step, in order.
TEST_P(ContactReportsTest, ReadLateTheyAreTheLastSteps) {
  World reference(SettingsFor(GetParam()));
  World late(SettingsFor(GetParam()));
  DropBoxes(&reference);
  DropBoxes(&late);
  std::vector<ContactReport> reference_log;
  int collisions = 0;
  for (int step = 0; step < 480; ++step) {
    reference.Step();
    late.Step();
    const std::vector<ContactReport> read_at_once = reference.contacts();
    for (const ContactReport& report : reference.TakeCollisionLog()) {
      reference_log.push_back(report);
      ++collisions;
    }
    if (step % 5 == 4) ExpectSameReports(late.contacts(), read_at_once, step);
  }
  EXPECT_GT(collisions, 0) << "the scene must hold collisions";
  ExpectSameReports(late.TakeCollisionLog(), reference_log, -1);
}

// Each call that changes what reports are made of (a body teleported,
// which drops its pairs; one destroyed, whose slot's generation moves on;
// one created; the settings changed), made after the step whose reports
// are read: those reports are still the step's.
TEST_P(ContactReportsTest, CallsBetweenStepAndReadKeepTheStepsReports) {
  using Call = std::function<void(World*, const std::vector<BodyId>&)>;
  const std::vector<std::pair<const char*, Call>> calls = {
      {"SetState",
       [](World* world, const std::vector<BodyId>& boxes) {
         ASSERT_TRUE(
             world->SetState(boxes[1], Translation(20, 0, 5), Vec3::Zero(), Vec3::Zero()).ok());
       }},
      {"DestroyBody",
       [](World* world, const std::vector<BodyId>& boxes) {
         ASSERT_TRUE(world->DestroyBody(boxes[1]).ok());
       }},
      {"CreateBody",
       [](World* world, const std::vector<BodyId>&) {
         BoxSpec spec;
         spec.world_from_body = Translation(-10, 0, 0.5);
         AddBox(world, spec);
       }},
      {"SetSettings",
       [](World* world, const std::vector<BodyId>&) {
         WorldSettings settings = world->settings();
         settings.time_step *= 0.5;
         ASSERT_TRUE(world->SetSettings(settings).ok());
       }},
  };
  for (const auto& [name, call] : calls) {
    SCOPED_TRACE(name);
    World reference(SettingsFor(GetParam()));
    World changed(SettingsFor(GetParam()));
    DropBoxes(&reference);
    const std::vector<BodyId> boxes = DropBoxes(&changed);
    for (int step = 0; step < 300; ++step) {
      reference.Step();
      changed.Step();
    }
    const std::vector<ContactReport> expected = reference.contacts();
    ASSERT_FALSE(expected.empty());
    call(&changed, boxes);
    ExpectSameReports(changed.contacts(), expected, 300);
  }
}

INSTANTIATE_TEST_SUITE_P(BothSolvers, ContactReportsTest,
                         ::testing::Values(MotionSolverKind::kExact, MotionSolverKind::kSoftStep));

}  // namespace
}  // namespace rigid_body_sim::physics
