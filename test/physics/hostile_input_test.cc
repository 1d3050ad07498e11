// Hostile input to the core: a body given a speed or a force that would
// overflow a step is frozen where it was, and its neighbours go on exactly
// as physics says; geometry builders refuse sizes they cannot build.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::physics {
namespace {

constexpr double kG = 9.81;

BodyDef UnitBoxAt(const Vec3& position) {
  BodyDef def;
  def.mass_properties = BoxMassProperties(1000.0, Vec3(1, 1, 1));
  ShapeDef shape;
  shape.geometry = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3(1, 1, 1)));
  def.shapes.push_back(shape);
  def.world_from_body.translation = position;
  return def;
}

bool Contains(const std::vector<BodyId>& ids, BodyId id) {
  for (const BodyId other : ids) {
    if (other == id) return true;
  }
  return false;
}

// A box flung at 1e300 m/s towards a neighbour 3 m down its path: the
// step's swept boxes and impulses would overflow. It is frozen at its pose
// before the step, reported once, and the neighbour falls freely: the
// integrator's free fall is exact for uniform gravity (free_flight_test).
TEST(StepGuardTest, HugeSpeedIsFrozenAndNeighbourFallsFreely) {
  World world;
  BodyDef flung = UnitBoxAt(Vec3(0, 0, 5));
  flung.linear_velocity = Vec3(1e300, 0, 0);
  const BodyId a = world.CreateBody(flung).value();
  const BodyId b = world.CreateBody(UnitBoxAt(Vec3(3, 0, 5))).value();

  world.Step();
  ASSERT_EQ(world.non_finite_bodies().size(), 1u);
  EXPECT_EQ(world.non_finite_bodies()[0], a);
  const int steps = 240;
  for (int i = 1; i < steps; ++i) {
    world.Step();
    EXPECT_TRUE(world.non_finite_bodies().empty()) << "reported again at step " << i;
  }
  EXPECT_EQ(world.GetPose(a).translation, Vec3(0, 0, 5));
  EXPECT_EQ(world.GetLinearVelocity(a), Vec3::Zero());
  EXPECT_EQ(world.GetAngularVelocity(a), Vec3::Zero());
  const double t = world.time();
  const Pose pose_b = world.GetPose(b);
  EXPECT_EQ(pose_b.translation.x(), 3.0);
  EXPECT_EQ(pose_b.translation.y(), 0.0);
  EXPECT_NEAR(pose_b.translation.z(), 5.0 - 0.5 * kG * t * t, 1e-9);
  EXPECT_NEAR(world.GetLinearVelocity(b).z(), -kG * t, 1e-9);
  EXPECT_TRUE(world.GetBody(b).HasFiniteState());
  for (const ContactReport& contact : world.contacts()) {
    EXPECT_FALSE(contact.body_a == a || contact.body_b == a);
  }
}

// Two forces of 1e308 N add up to infinity, which would make the momentum
// infinite and the position NaN. The body stays at its pose, turned as it
// was; the neighbour glides on at 1 m/s (no gravity): y = t.
TEST(StepGuardTest, OverflowingForceIsFrozenAtItsPose) {
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  World world(settings);
  BodyDef pushed = UnitBoxAt(Vec3(0, 0, 0));
  pushed.world_from_body.rotation = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
  pushed.linear_velocity = Vec3(0.5, 0, 0);
  const BodyId a = world.CreateBody(pushed).value();
  BodyDef neighbour = UnitBoxAt(Vec3(2, 0, 0));
  neighbour.linear_velocity = Vec3(0, 1, 0);
  const BodyId b = world.CreateBody(neighbour).value();

  ASSERT_TRUE(world.ApplyForceAtPoint(a, Vec3(1e308, 0, 0), Vec3(0, 0, 0)).ok());
  ASSERT_TRUE(world.ApplyForceAtPoint(a, Vec3(1e308, 0, 0), Vec3(0, 0, 0)).ok());
  world.Step();
  ASSERT_EQ(world.non_finite_bodies().size(), 1u);
  EXPECT_EQ(world.non_finite_bodies()[0], a);
  for (int i = 0; i < 99; ++i) world.Step();
  const Pose pose_a = world.GetPose(a);
  EXPECT_EQ(pose_a.translation, Vec3(0, 0, 0));
  EXPECT_NEAR(pose_a.rotation.angularDistance(pushed.world_from_body.rotation), 0.0, 1e-15);
  EXPECT_EQ(world.GetLinearVelocity(a), Vec3::Zero());
  EXPECT_NEAR(world.GetPose(b).translation.y(), world.time(), 1e-12);
  EXPECT_EQ(world.GetPose(b).translation.x(), 2.0);
  EXPECT_EQ(world.GetLinearVelocity(b), Vec3(0, 1, 0));
}

// 1e200 rad/s: the drift's rotation angle alone is finite, but the angular
// momentum times the lever arms of a contact is not.
TEST(StepGuardTest, HugeSpinIsFrozen) {
  World world;
  BodyDef spun = UnitBoxAt(Vec3(0, 0, 2));
  spun.angular_velocity = Vec3(0, 0, 1e200);
  const BodyId a = world.CreateBody(spun).value();
  world.Step();
  EXPECT_TRUE(Contains(world.non_finite_bodies(), a));
  EXPECT_EQ(world.GetPose(a).translation, Vec3(0, 0, 2));
  EXPECT_EQ(world.GetAngularVelocity(a), Vec3::Zero());
}

// SetState gives a frozen body a state again, and it moves as any other:
// x = 2 t with no gravity.
TEST(StepGuardTest, SetStateRevivesFrozenBody) {
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  World world(settings);
  BodyDef flung = UnitBoxAt(Vec3(0, 0, 0));
  flung.linear_velocity = Vec3(0, 0, -1e150);
  const BodyId a = world.CreateBody(flung).value();
  world.Step();
  ASSERT_TRUE(Contains(world.non_finite_bodies(), a));
  ASSERT_TRUE(world.SetState(a, Pose::Identity(), Vec3(2, 0, 0), Vec3::Zero()).ok());
  world.Restart();
  for (int i = 0; i < 120; ++i) {
    world.Step();
    ASSERT_TRUE(world.non_finite_bodies().empty());
  }
  EXPECT_NEAR(world.GetPose(a).translation.x(), 2.0 * world.time(), 1e-12);
  EXPECT_EQ(world.GetLinearVelocity(a), Vec3(2, 0, 0));
}

// A 0.1 um x 0.1 um x 1 m box has side faces of area 1e-7 m^2, degenerate
// against its 1 m diagonal: refused with its size, not built.
TEST(HostileGeometryTest, DegenerateBoxIsRefusedNotBuilt) {
  const Result<ConvexPolyhedron> box = TryMakeBoxPolyhedron(Vec3(1e-7, 1e-7, 1));
  ASSERT_FALSE(box.ok());
  EXPECT_NE(box.message().find("degenerate"), std::string::npos) << box.message();
  EXPECT_FALSE(TryMakeBoxPolyhedron(Vec3(std::nan(""), 1, 1)).ok());
  EXPECT_FALSE(TryMakeBoxPolyhedron(Vec3(-1, 1, 1)).ok());
  const Result<ConvexPolyhedron> unit = TryMakeBoxPolyhedron(Vec3(1, 2, 3));
  ASSERT_TRUE(unit.ok());
  EXPECT_EQ(unit->vertices.size(), 8u);
  EXPECT_EQ(unit->faces.size(), 6u);
}

TEST(HostileGeometryTest, CylinderBuilderRefusesBadInput) {
  EXPECT_FALSE(TryMakeCylinderPolyhedron(std::nan(""), 1, 32).ok());
  EXPECT_FALSE(TryMakeCylinderPolyhedron(1, std::numeric_limits<double>::infinity(), 32).ok());
  EXPECT_FALSE(TryMakeCylinderPolyhedron(1, 1, 2).ok());
  const Result<ConvexPolyhedron> cylinder = TryMakeCylinderPolyhedron(0.5, 2, 16);
  ASSERT_TRUE(cylinder.ok());
  // 16 sides and two caps.
  EXPECT_EQ(cylinder->faces.size(), 18u);
  EXPECT_EQ(cylinder->vertices.size(), 32u);
}

}  // namespace
}  // namespace rigid_body_sim::physics
