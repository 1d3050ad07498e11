// Bad input to the world is refused with a message and changes nothing.
#include <limits>

#include <gtest/gtest.h>

#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::physics {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

BodyDef UnitBox() {
  BodyDef def;
  def.mass_properties = BoxMassProperties(1.0, Vec3(1, 1, 1));
  ShapeDef shape;
  shape.geometry = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3(1, 1, 1)));
  def.shapes.push_back(shape);
  def.world_from_body.translation = Vec3(0, 0, 1);
  return def;
}

class WorldInputTest : public ::testing::Test {
 protected:
  void SetUp() override { existing_ = world_.CreateBody(UnitBox()).value(); }

  void ExpectRefused(const BodyDef& def, const std::string& expected_words) {
    const Pose pose_before = world_.GetPose(existing_);
    const Result<BodyId> result = world_.CreateBody(def);
    ASSERT_FALSE(result.ok());
    EXPECT_NE(result.message().find(expected_words), std::string::npos) << result.message();
    EXPECT_EQ(world_.BodyCount(), 1u);
    EXPECT_EQ(world_.GetPose(existing_).translation, pose_before.translation);
  }

  World world_;
  BodyId existing_;
};

// The motion solver is chosen by a setting; a kind that is none is refused
// and the world keeps its settings.
TEST_F(WorldInputTest, RefusesAMotionSolverThatIsNone) {
  WorldSettings settings;
  EXPECT_TRUE(ValidateWorldSettings(settings).ok());
  settings.motion_solver = static_cast<MotionSolverKind>(7);
  const Status status = ValidateWorldSettings(settings);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("motion_solver 7"), std::string::npos) << status.message();
  World world;
  EXPECT_FALSE(world.SetSettings(settings).ok());
  EXPECT_EQ(world.settings().motion_solver, MotionSolverKind::kExact);
}

TEST_F(WorldInputTest, RefusesNonFinitePose) {
  BodyDef def = UnitBox();
  def.world_from_body.translation.x() = kNaN;
  ExpectRefused(def, "position");
  def = UnitBox();
  def.world_from_body.rotation.coeffs() << kInf, 0, 0, 1;
  ExpectRefused(def, "quaternion");
}

TEST_F(WorldInputTest, RefusesZeroQuaternion) {
  BodyDef def = UnitBox();
  def.world_from_body.rotation.coeffs().setZero();
  ExpectRefused(def, "unit");
}

TEST_F(WorldInputTest, RefusesNonFiniteVelocity) {
  BodyDef def = UnitBox();
  def.linear_velocity.z() = kInf;
  ExpectRefused(def, "linear velocity");
  def = UnitBox();
  def.angular_velocity.y() = kNaN;
  ExpectRefused(def, "angular velocity");
}

TEST_F(WorldInputTest, RefusesZeroAndNegativeMass) {
  BodyDef def = UnitBox();
  def.mass_properties.mass = 0.0;
  ExpectRefused(def, "mass");
  def.mass_properties.mass = -1.0;
  ExpectRefused(def, "mass");
}

TEST_F(WorldInputTest, RefusesInertiaThatIsNotPositiveDefinite) {
  BodyDef def = UnitBox();
  def.mass_properties.inertia_about_com = Mat3::Identity();
  def.mass_properties.inertia_about_com(2, 2) = -0.1;
  ExpectRefused(def, "inertia");
}

TEST_F(WorldInputTest, StaticBodyNeedsNoMass) {
  BodyDef def = UnitBox();
  def.is_static = true;
  def.mass_properties = MassProperties();
  ASSERT_TRUE(world_.CreateBody(def).ok());
  EXPECT_EQ(world_.BodyCount(), 2u);
}

TEST_F(WorldInputTest, StaticBodyDoesNotMove) {
  BodyDef def = UnitBox();
  def.is_static = true;
  const BodyId id = world_.CreateBody(def).value();
  ASSERT_TRUE(world_.ApplyForceAtPoint(id, Vec3(100, 0, 0), Vec3::Zero()).ok());
  for (int i = 0; i < 10; ++i) world_.Step();
  EXPECT_EQ(world_.GetPose(id).translation, def.world_from_body.translation);
}

TEST_F(WorldInputTest, SetStateRefusesNaNAndKeepsState) {
  const Pose before = world_.GetPose(existing_);
  Pose bad = before;
  bad.translation.y() = kNaN;
  EXPECT_FALSE(world_.SetState(existing_, bad, Vec3::Zero(), Vec3::Zero()).ok());
  EXPECT_EQ(world_.GetPose(existing_).translation, before.translation);
}

TEST_F(WorldInputTest, SetStateTeleportsAndSetsTwistOfBodyOrigin) {
  Pose target;
  target.translation = Vec3(3, 4, 5);
  target.rotation = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  const Vec3 v(1, 0, 0);
  const Vec3 w(0, 0, 2);
  ASSERT_TRUE(world_.SetState(existing_, target, v, w).ok());
  EXPECT_LT((world_.GetPose(existing_).translation - target.translation).norm(), 1e-12);
  EXPECT_LT(world_.GetPose(existing_).rotation.angularDistance(target.rotation), 1e-12);
  EXPECT_LT((world_.GetLinearVelocity(existing_) - v).norm(), 1e-12);
  EXPECT_LT((world_.GetAngularVelocity(existing_) - w).norm(), 1e-12);
}

TEST_F(WorldInputTest, DestroyedIdIsInvalidAfterSlotReuse) {
  ASSERT_TRUE(world_.DestroyBody(existing_).ok());
  EXPECT_FALSE(world_.IsValid(existing_));
  EXPECT_FALSE(world_.DestroyBody(existing_).ok());
  const BodyId reused = world_.CreateBody(UnitBox()).value();
  EXPECT_EQ(reused.index, existing_.index);
  EXPECT_FALSE(world_.IsValid(existing_));
  EXPECT_TRUE(world_.IsValid(reused));
}

TEST_F(WorldInputTest, RefusesBadSettings) {
  WorldSettings settings;
  settings.time_step = -0.01;
  EXPECT_FALSE(world_.SetSettings(settings).ok());
  EXPECT_DOUBLE_EQ(world_.settings().time_step, 1.0 / 240.0);
  settings.time_step = 0.01;
  settings.gravity.x() = kNaN;
  EXPECT_FALSE(world_.SetSettings(settings).ok());
  settings = WorldSettings();
  settings.sleep.speeding_up_time = -0.1;
  EXPECT_FALSE(world_.SetSettings(settings).ok());
  EXPECT_DOUBLE_EQ(world_.settings().sleep.speeding_up_time,
                   WorldSettings().sleep.speeding_up_time);
}

}  // namespace
}  // namespace rigid_body_sim::physics
