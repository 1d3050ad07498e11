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

// With restitution 0, a box (face down) and a ball dropped from 1 m meet the
// ground at free fall's sqrt(2 g h), at 240 and at 60 Hz: the collision
// resolved at the time of impact reports that approach speed to 1e-6, no
// step before it is slowed, and the step of the impact ends at rest.
TEST(ImpactTest, InelasticLandingIsAtFreeFallSpeed) {
  const double drop = 1.0;
  const double landing_speed = std::sqrt(2.0 * kG * drop);
  for (const double hz : {240.0, 60.0}) {
    for (const bool ball : {false, true}) {
      SCOPED_TRACE(::testing::Message() << hz << " Hz, " << (ball ? "ball" : "box"));
      WorldSettings settings;
      settings.time_step = 1.0 / hz;
      World world(settings);
      AddGround(&world, MakeMaterial(0.5, 0.0));
      BodyId body;
      if (ball) {
        SphereSpec spec;
        spec.radius = 0.5;
        spec.world_from_body = Translation(0, 0, 0.5 + drop);
        spec.material = MakeMaterial(0.5, 0.0);
        body = AddSphere(&world, spec);
      } else {
        BoxSpec spec;
        spec.world_from_body = Translation(0, 0, 0.5 + drop);
        spec.material = MakeMaterial(0.5, 0.0);
        body = AddBox(&world, spec);
      }
      const double impact_time = std::sqrt(2.0 * drop / kG);
      std::vector<ContactReport> collisions;
      while (world.time() < impact_time - 1e-12) {
        world.Step();
        const double vz = world.GetLinearVelocity(body).z();
        if (world.time() < impact_time) {
          EXPECT_NEAR(vz, -kG * world.time(), 1e-12 * kG * world.time()) << world.time();
        } else {
          EXPECT_NEAR(vz, 0.0, 1e-6) << world.time();
        }
        for (const ContactReport& report : world.TakeCollisionLog()) collisions.push_back(report);
      }
      ASSERT_FALSE(collisions.empty());
      for (const ContactReport& collision : collisions) {
        EXPECT_NEAR(-collision.normal_velocity / landing_speed, 1.0, 1e-6);
      }
    }
  }
}

// A ball fired at 40 m/s along a row of boxes, 2 cm above their tops, into
// a wall: it never touches the boxes, so no contact with them is ever
// reported, and every colliding contact reported (with the wall) carries
// an impulse.
TEST(ImpactTest, OnlyResolvedCollisionsAreReportedAsColliding) {
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  World world(settings);
  AddGround(&world, MakeMaterial(0.5, 0.0));
  std::vector<BodyId> row;
  for (int i = 0; i < 10; ++i) {
    BoxSpec box;
    box.size = Vec3(0.5, 0.5, 0.5);
    box.world_from_body = Translation(1.0 + 0.6 * i, 0, 0.25);
    box.is_static = i % 2 == 0;
    row.push_back(AddBox(&world, box));
  }
  BoxSpec wall;
  wall.size = Vec3(0.2, 4.0, 4.0);
  wall.is_static = true;
  wall.world_from_body = Translation(8.0, 0, 2.0);
  const BodyId wall_id = AddBox(&world, wall);
  SphereSpec ball;
  ball.radius = 0.1;
  ball.world_from_body = Translation(0, 0, 0.5 + 0.02 + 0.1);
  ball.linear_velocity = Vec3(40.0, 0, 0);
  ball.material = MakeMaterial(0.5, 0.5);
  const BodyId ball_id = AddSphere(&world, ball);
  int wall_collisions = 0;
  for (int step = 0; step < 60; ++step) {
    world.Step();
    for (const ContactReport& report : world.contacts()) {
      if (report.type == ContactType::kColliding) EXPECT_GT(report.normal_impulse, 0.0);
      if (report.body_a != ball_id && report.body_b != ball_id) continue;
      const BodyId other = report.body_a == ball_id ? report.body_b : report.body_a;
      EXPECT_TRUE(other == wall_id) << "step " << step;
      wall_collisions += report.type == ContactType::kColliding;
    }
  }
  EXPECT_GE(wall_collisions, 1);
  EXPECT_NEAR(world.GetLinearVelocity(ball_id).x(), -20.0, 1e-9);
}

// A small body dropped from 3 m with a tumble lands on a corner at 7.7 m/s
// spinning at hundreds of rad/s. It must come to rest within 3 s on a face
// (z = half an edge, less the penetration slop), and at no step may its pose
// stand still while it still moves (held at the start of its step, it would
// freeze there with its velocity). A pair's contact margin is scaled down to
// the body (a quarter of its thickness), so a 2 mm cube's bottom corners are
// not traded for its top ones when its manifold is reduced to four points.
struct SmallBody {
  Vec3 size;  // m; a sphere when only x is set
  bool sphere = false;
};

struct Settled {
  bool asleep = false;
  int frozen_steps = 0;
};

Settled DropAndSettle(World* world, BodyId body) {
  Settled settled;
  while (world->time() < 3.0 && world->GetBody(body).awake) {
    const Pose before = world->GetPose(body);
    world->Step();
    const Pose after = world->GetPose(body);
    const bool still = after.translation == before.translation &&
                       after.rotation.coeffs() == before.rotation.coeffs();
    if (still && world->GetLinearVelocity(body).norm() > 1e-3) ++settled.frozen_steps;
  }
  settled.asleep = !world->GetBody(body).awake;
  return settled;
}

BodyId AddSmallBody(World* world, const SmallBody& small, const Vec3& position) {
  const Quat tumble(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  if (small.sphere) {
    SphereSpec spec;
    spec.radius = 0.5 * small.size.x();
    spec.mass = 1000.0 * std::pow(small.size.x(), 3);
    spec.world_from_body = Pose{position, tumble};
    spec.material = MakeMaterial(0.5, 0.0);
    return AddSphere(world, spec);
  }
  BoxSpec spec;
  spec.size = small.size;
  spec.mass = 1000.0 * small.size.prod();
  spec.world_from_body = Pose{position, tumble};
  spec.angular_velocity = Vec3(1.0, -2.0, 0.5);
  spec.material = MakeMaterial(0.5, 0.0);
  return AddBox(world, spec);
}

// The centre's height above a support at z = 0 when resting on a face: half
// of one of the box's edges, or the radius.
bool RestsOnAFace(const SmallBody& small, double z, double tolerance) {
  if (small.sphere) return std::abs(z - 0.5 * small.size.x()) <= tolerance;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(z - 0.5 * small.size[axis]) <= tolerance) return true;
  }
  return false;
}

TEST(ImpactTest, SmallBodiesComeToRestOnAFace) {
  const std::vector<SmallBody> bodies = {
      {Vec3::Constant(0.002)},     {Vec3::Constant(0.005)},       {Vec3::Constant(0.01)},
      {Vec3::Constant(0.02)},      {Vec3::Constant(0.002), true}, {Vec3::Constant(0.02), true},
      {Vec3(0.016, 0.009, 0.011)},
  };
  for (const SmallBody& small : bodies) {
    SCOPED_TRACE(::testing::Message() << small.size.transpose() << (small.sphere ? " sphere" : ""));
    World world;
    AddGround(&world, MakeMaterial(0.8, 0.0));
    const BodyId body = AddSmallBody(&world, small, Vec3(0, 0, 3.0));
    const Settled settled = DropAndSettle(&world, body);
    EXPECT_TRUE(settled.asleep);
    EXPECT_EQ(settled.frozen_steps, 0);
    const double z = world.GetPose(body).translation.z();
    EXPECT_TRUE(RestsOnAFace(small, z, world.settings().solver.penetration_slop + 1e-9))
        << "z = " << z;
  }
}

// Small bodies dropped from 3 m onto a resting 2 cm cube: each comes to rest
// on a face, on the cube's top (z = 2 cm + half an edge) or beside it on the
// ground (z = half an edge), and is never frozen on the way.
TEST(ImpactTest, SmallBodiesDroppedOntoACubeComeToRest) {
  // (A sphere would roll off the cube and on along the ground for ever.)
  for (const SmallBody& small : {SmallBody{Vec3::Constant(0.002)}, SmallBody{Vec3::Constant(0.005)},
                                 SmallBody{Vec3(0.008, 0.005, 0.006)}}) {
    SCOPED_TRACE(::testing::Message() << small.size.transpose() << (small.sphere ? " sphere" : ""));
    World world;
    AddGround(&world, MakeMaterial(0.8, 0.0));
    BoxSpec base;
    base.size = Vec3::Constant(0.02);
    base.mass = 8e-3;
    base.world_from_body = Translation(0, 0, 0.01);
    base.material = MakeMaterial(0.5, 0.0);
    AddBox(&world, base);
    const BodyId body = AddSmallBody(&world, small, Vec3(0.001, 0.002, 3.0));
    const Settled settled = DropAndSettle(&world, body);
    EXPECT_TRUE(settled.asleep);
    EXPECT_EQ(settled.frozen_steps, 0);
    const double z = world.GetPose(body).translation.z();
    const double tolerance = 2.0 * world.settings().solver.penetration_slop + 1e-9;
    EXPECT_TRUE(RestsOnAFace(small, z, tolerance) || RestsOnAFace(small, z - 0.02, tolerance))
        << "z = " << z;
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
