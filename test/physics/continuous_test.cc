// No tunnelling: fast bodies are backed up to their time of impact
// (Baraff 1997, "Rigid Body Simulation II", section 6) instead of passing through thin walls.
#include <algorithm>
#include <array>
#include <limits>
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
using testing::SphereSpec;
using testing::Translation;

// A static wall 5 cm thick whose near face is at x = 0.
BodyId AddWall(World* world) {
  BoxSpec wall;
  wall.size = Vec3(0.05, 4.0, 4.0);
  wall.is_static = true;
  wall.world_from_body = Translation(0.025, 0, 0);
  wall.material = MakeMaterial(0.5, 0.0);
  return AddBox(world, wall);
}

WorldSettings ZeroGravity() {
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  return settings;
}

// Corners of a box of `size` (m) in world coordinates.
std::array<Vec3, 8> Corners(const World& world, BodyId id, const Vec3& size) {
  const Pose world_from_body = world.GetPose(id);
  std::array<Vec3, 8> corners;
  for (int i = 0; i < 8; ++i) {
    const Vec3 local(0.5 * size.x() * (i & 1 ? 1 : -1), 0.5 * size.y() * (i & 2 ? 1 : -1),
                     0.5 * size.z() * (i & 4 ? 1 : -1));
    corners[i] = world_from_body * local;
  }
  return corners;
}

// Body::travel grows each step by at least how far any point of the body
// moved: the narrow phase leaves a pair found apart by a gap g untested
// while its bodies' travel stays below g less the contact distance, so an
// underestimate would miss contacts. Boxes thrown spinning at each other
// and the ground: free flight, impacts, time-of-impact back-ups, sliding,
// split-impulse pushes and resting.
TEST(ContinuousTest, TravelBoundsHowFarEveryPointOfABodyMoves) {
  World world;
  AddGround(&world, MakeMaterial(0.5, 0.0));
  const Vec3 size(0.6, 0.4, 0.2);
  std::vector<BodyId> boxes;
  for (int i = 0; i < 12; ++i) {
    BoxSpec spec;
    spec.size = size;
    const double side = i % 2 == 0 ? -1.0 : 1.0;
    spec.world_from_body = Translation(side * (1.0 + 0.1 * i), 0.05 * i, 0.3 + 0.35 * i);
    spec.linear_velocity = Vec3(-side * (2.0 + 0.3 * i), 0.2 * (i % 3), -1.0);
    spec.angular_velocity = Vec3(3.0 - 0.5 * i, 0.7 * i, side * 4.0);
    spec.material = MakeMaterial(0.5, i % 3 == 0 ? 0.5 : 0.0);
    boxes.push_back(AddBox(&world, spec));
  }
  double largest_ratio = 0.0;  // of a corner's motion to the travel it added
  for (int step = 0; step < 240 * 2; ++step) {
    std::vector<std::array<Vec3, 8>> before;
    std::vector<double> travel_before;
    for (const BodyId box : boxes) {
      before.push_back(Corners(world, box, size));
      travel_before.push_back(world.GetBody(box).travel);
    }
    world.Step();
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      const std::array<Vec3, 8> after = Corners(world, boxes[b], size);
      const double added = world.GetBody(boxes[b]).travel - travel_before[b];
      for (int i = 0; i < 8; ++i) {
        const double moved = (after[i] - before[b][i]).norm();
        EXPECT_LE(moved, added + 1e-12) << "step " << step << ", box " << b << ", corner " << i;
        if (added > 0.0) largest_ratio = std::max(largest_ratio, moved / added);
      }
    }
  }
  // The bound is not loose by orders of magnitude either.
  EXPECT_GT(largest_ratio, 0.5);
}

TEST(ContinuousTest, ThinBoxAtTwoHundredMetresPerSecondDoesNotPassAWall) {
  World world(ZeroGravity());
  AddWall(&world);
  BoxSpec bullet;
  bullet.size = Vec3(0.02, 0.2, 0.2);
  bullet.world_from_body = Translation(-1.3, 0.1, -0.2);
  bullet.linear_velocity = Vec3(200.0, 0, 0);
  bullet.material = MakeMaterial(0.5, 0.0);
  const BodyId id = AddBox(&world, bullet);
  double furthest = -std::numeric_limits<double>::infinity();
  for (int step = 0; step < 240; ++step) {
    world.Step();
    furthest = std::max(furthest, world.GetPose(id).translation.x() + 0.5 * bullet.size.x());
  }
  // Its front face never goes deeper than the penetration slop into the wall.
  EXPECT_LT(furthest, world.settings().solver.penetration_slop);
  EXPECT_LT(world.GetPose(id).translation.x(), 0.0);
}

TEST(ContinuousTest, CentimetreSphereAtFiveHundredMetresPerSecondDoesNotPassAWall) {
  World world(ZeroGravity());
  AddWall(&world);
  SphereSpec bullet;
  bullet.radius = 0.005;
  bullet.mass = 0.01;
  bullet.world_from_body = Translation(-3.0, 0.3, 0.1);
  bullet.linear_velocity = Vec3(500.0, 0, 0);
  bullet.material = MakeMaterial(0.5, 0.5);
  const BodyId id = AddSphere(&world, bullet);
  double furthest = -std::numeric_limits<double>::infinity();
  bool hit = false;
  for (int step = 0; step < 240; ++step) {
    world.Step();
    furthest = std::max(furthest, world.GetPose(id).translation.x() + bullet.radius);
    for (const ContactReport& contact : world.contacts()) {
      hit |= contact.type == ContactType::kColliding && contact.body_a == id;
    }
  }
  ASSERT_TRUE(hit);
  EXPECT_LT(furthest, world.settings().solver.penetration_slop);
  // With e = 0.5 it leaves at 250 m/s the way it came.
  EXPECT_NEAR(world.GetLinearVelocity(id).x(), -250.0, 1e-6 * 250.0);
}

// A body whose state overflows is taken out of the simulation and reported;
// its neighbours never see a NaN.
TEST(ContinuousTest, BodyWithNonFiniteStateIsExcludedAndReported) {
  World world;
  testing::AddGround(&world, MakeMaterial(0.5, 0.0));
  BoxSpec spec;
  spec.world_from_body = Translation(0, 0, 0.5);
  spec.material = MakeMaterial(0.5, 0.0);
  const BodyId victim = AddBox(&world, spec);
  spec.world_from_body = Translation(0, 0, 1.5);
  const BodyId neighbour = AddBox(&world, spec);
  // Each force is finite; their sum overflows to infinity.
  ASSERT_TRUE(world.ApplyForceAtPoint(victim, Vec3(0, 0, 1e308), Vec3(0.5, 0.5, 0.5)).ok());
  ASSERT_TRUE(world.ApplyForceAtPoint(victim, Vec3(0, 0, 1e308), Vec3(0.5, 0.5, 0.5)).ok());
  world.Step();
  ASSERT_EQ(world.non_finite_bodies().size(), 1u);
  EXPECT_EQ(world.non_finite_bodies()[0], victim);
  for (int step = 0; step < 240; ++step) world.Step();
  EXPECT_TRUE(world.GetPose(neighbour).translation.allFinite());
  EXPECT_TRUE(world.GetLinearVelocity(neighbour).allFinite());
  // With the victim gone from under it, the neighbour falls to the ground.
  EXPECT_NEAR(world.GetPose(neighbour).translation.z(), 0.5, 2e-3);
  for (const ContactReport& contact : world.contacts()) {
    EXPECT_NE(contact.body_a, victim);
    EXPECT_NE(contact.body_b, victim);
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics
