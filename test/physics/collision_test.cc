// Colliding contact: impulses with restitution (Baraff 1997,
// "Rigid Body Simulation II", section 8, eqs. (8-7)-(8-18)).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "scene.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::AddGround;
using testing::AddSphere;
using testing::BoxSpec;
using testing::KineticEnergy;
using testing::MakeMaterial;
using testing::SphereSpec;
using testing::Translation;

// A world whose bodies never sleep, on the ground z <= 0 of `ground`.
World WorldWithoutSleepOnGround(const Material& ground) {
  WorldSettings settings;
  settings.sleep.enabled = false;
  World world(settings);
  AddGround(&world, ground);
  return world;
}

// A unit cube tipped 0.7 rad onto one bottom edge and released falls back
// onto its face. Rotating about that edge it lands at
// omega- = sqrt(2 g (h(0.7) - 1/2) / I_edge), h(phi) = (cos phi + sin phi) / 2
// the height of its centre, I_edge = 2/3 kg m^2. The impact of the far edge
// (e = 0, no slip with mu = 10) keeps the angular momentum about that edge:
// omega+ = (1 - 3/2 sin^2 alpha) omega- = omega- / 4 for a cube, alpha = 45
// degrees (Housner 1963, "The behavior of inverted pendulum structures
// during earthquakes", Bull. Seismol. Soc. Am. 53(2), eq. (2)). After the
// impact the cube turns about the new edge, slowed by gravity at
// alpha_g = g (1/2) / I_edge for the rest of the step, so at the end of the
// step omega lies in [omega- / 4 - alpha_g dt, omega- / 4].
TEST(CollisionTest, ToppledCubeKeepsAQuarterOfItsSpin) {
  constexpr double kTilt = 0.7;  // rad, below 45 degrees: it falls back
  const double g = 9.81;
  World world = WorldWithoutSleepOnGround(MakeMaterial(10.0, 0.0));
  BoxSpec spec;
  spec.material = MakeMaterial(10.0, 0.0);
  const Quat tilt(Eigen::AngleAxisd(-kTilt, Vec3::UnitY()));
  // The edge x = -1/2, z = -1/2 of the box at the origin of the ground.
  spec.world_from_body = Pose{-(tilt * Vec3(-0.5, 0.0, -0.5)), tilt};
  const BodyId cube = AddBox(&world, spec);
  const double drop = 0.5 * (std::cos(kTilt) + std::sin(kTilt)) - 0.5;
  const double inertia = 2.0 / 3.0;
  const double before = std::sqrt(2.0 * g * drop / inertia);
  const double slowing = g * 0.5 / inertia * world.settings().time_step;
  double previous = 0.0;
  double after = -1.0;
  for (int step = 0; step < 480 && after < 0.0; ++step) {
    world.Step();
    const double spin = world.GetAngularVelocity(cube).y();
    if (spin < 0.5 * previous) after = spin;
    previous = spin;
  }
  std::printf("omega- %.4f rad/s, omega+ %.4f rad/s (%.4f of omega-)\n", before, after,
              after / before);
  EXPECT_LE(after, 0.25 * before + 1e-3);
  EXPECT_GE(after, 0.25 * before - slowing - 1e-3);
  // The motion is symmetric about the xz plane: no turn about x beyond what
  // the sweeps' stop at velocity_tolerance (1e-6 m/s at 0.5 m) leaves.
  EXPECT_NEAR(world.GetAngularVelocity(cube).x(), 0.0, 1e-5);
}

// An eccentric body: 1 kg whose only shape, a 0.2 m box, sits 1 m from its
// centre of mass, I = 0.05 kg m^2, tilted 0.3 rad and dropped 1 m with
// e = 1 and mu = 0.5. An impact never adds energy; with Poisson's
// restitution e j_c after a frictional compression this one did (it left
// the ground with 32 J more than the 9.8 J it fell with), so a collision
// round applies only as much of its restitution as adds none
// (ContactSolver::ApplyRestitution). Over 4 s of bounces the mechanical
// energy stays at most its start, within what the split impulse can lift a
// body: the penetration slop, m g 1e-4 m.
TEST(CollisionTest, EccentricFrictionalImpactAddsNoEnergy) {
  constexpr double kInertia = 0.05;  // kg m^2, about every axis
  const double g = 9.81;
  World world = WorldWithoutSleepOnGround(MakeMaterial(0.5, 1.0));
  BodyDef def;
  def.world_from_body = Pose{Vec3(0.0, 0.0, 1.0), Quat(Eigen::AngleAxisd(0.3, Vec3::UnitY()))};
  def.mass_properties.mass = 1.0;
  def.mass_properties.inertia_about_com = Mat3::Identity() * kInertia;
  ShapeDef box;
  box.geometry = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3::Constant(0.2)));
  box.body_from_shape.translation = Vec3(1.0, 0.0, 0.0);
  box.material = MakeMaterial(0.5, 1.0);
  def.shapes.push_back(box);
  const BodyId body = world.CreateBody(def).value();
  auto energy = [&] {
    const Body& state = world.GetBody(body);
    return 0.5 * state.linear_velocity.squaredNorm() +
           0.5 * kInertia * state.angular_velocity.squaredNorm() + g * state.position.z();
  };
  const double start = energy();
  double highest = start;
  int impacts = 0;
  for (int step = 0; step < 4 * 240; ++step) {
    world.Step();
    highest = std::max(highest, energy());
    for (const ContactReport& contact : world.contacts()) {
      impacts += contact.type == ContactType::kColliding;
    }
  }
  std::printf("%d colliding points; energy at most %.9f J against %.9f J at the start\n", impacts,
              highest, start);
  EXPECT_GT(impacts, 0);
  EXPECT_LE(highest, start + g * WorldSettings().solver.penetration_slop);
}

// A ball dropped from h rises e^2 h after its first bounce and e^(2n) h after
// its n-th, measured from where it struck. Flight between bounces conserves
// energy, so the n-th rise is v^2 / (2 g) with v the approach speed of
// bounce n + 1, which the contact reports; the first apex is also sampled
// directly.
class BounceTest : public ::testing::TestWithParam<double> {};

TEST_P(BounceTest, RisesToRestitutionSquaredTimesDropHeight) {
  const double e = GetParam();
  const double g = 9.81;
  const double h = 1.0;
  const double radius = 0.1;
  World world;
  const BodyId ground = AddGround(&world, MakeMaterial(0.5, 0.0));
  SphereSpec spec;
  spec.radius = radius;
  spec.world_from_body = Translation(0, 0, h + radius);
  spec.material = MakeMaterial(0.5, e);
  const BodyId ball = AddSphere(&world, spec);

  std::vector<double> approach_speeds;
  double first_apex = 0.0;
  for (int step = 0; step < 240 * 6 && approach_speeds.size() < 4; ++step) {
    world.Step();
    for (const ContactReport& contact : world.contacts()) {
      if (contact.body_a == ball && contact.body_b == ground &&
          contact.type == ContactType::kColliding) {
        approach_speeds.push_back(-contact.normal_velocity);
      }
    }
    if (approach_speeds.size() == 1) {
      first_apex = std::max(first_apex, world.GetPose(ball).translation.z() - radius);
    }
  }
  ASSERT_EQ(approach_speeds.size(), 4u);
  EXPECT_NEAR(approach_speeds[0] / std::sqrt(2.0 * g * h), 1.0, 1e-3);
  EXPECT_NEAR(first_apex / (e * e * h), 1.0, 0.02);
  for (int n = 1; n <= 3; ++n) {
    const double rise = approach_speeds[n] * approach_speeds[n] / (2.0 * g);
    const double expected = std::pow(e, 2 * n) * h;
    EXPECT_NEAR(rise / expected, 1.0, 0.02)
        << "bounce " << n << ": rose " << rise << " m, expected " << expected << " m";
  }
}

INSTANTIATE_TEST_SUITE_P(Restitution, BounceTest, ::testing::Values(0.2, 0.5, 0.9));

TEST(CollisionTest, InelasticBoxDroppedFlatComesToRestWithoutRebound) {
  World world;
  AddGround(&world, MakeMaterial(0.5, 0.0));
  BoxSpec spec;
  spec.world_from_body = Translation(0, 0, 1.5);
  spec.material = MakeMaterial(0.5, 0.0);
  const BodyId box = AddBox(&world, spec);
  double lowest = 1e9;
  double highest_after_landing = -1e9;
  bool landed = false;
  for (int step = 0; step < 240 * 3; ++step) {
    world.Step();
    const double z = world.GetPose(box).translation.z();
    if (!landed && world.GetLinearVelocity(box).z() > -1e-6 && z < 0.51) landed = true;
    if (landed) {
      lowest = std::min(lowest, z);
      highest_after_landing = std::max(highest_after_landing, z);
    }
  }
  ASSERT_TRUE(landed);
  EXPECT_LT(highest_after_landing - lowest, 1e-3);
  EXPECT_NEAR(world.GetPose(box).translation.z(), 0.5, 2e-3);
  EXPECT_LT(world.GetLinearVelocity(box).norm(), 1e-3);
}

// A box strikes the ground on one corner with given v and omega. The result
// must equal Baraff's impulse computed by hand (Baraff 1997,
// "Rigid Body Simulation II", eq. (8-18)):
// j = -(1+e) v_r / (1/M + n.(I^-1 (r x n)) x r), P += j n, L += r x j n.
// An inelastic box landing flat at 5 m/s on a static box yawed 0.1 rad
// against it: the impact stops it at every corner at once, so it neither
// tips nor slides (no horizontal motion, no spin), does not sink into the
// box below by more than a step's worth of gravity beyond the slop, and the
// reported collision impulse is the momentum it brought, m v.
TEST(CollisionTest, InelasticFaceLandingStopsAtEveryCornerAtOnce) {
  World world;
  BoxSpec base;
  base.size = Vec3(1.0, 1.0, 1.0);
  base.is_static = true;
  base.world_from_body.rotation = Quat(Eigen::AngleAxisd(0.1, Vec3::UnitZ()));
  base.material = MakeMaterial(0.5, 0.0);
  AddBox(&world, base);
  BoxSpec spec;
  spec.mass = 2.0;
  spec.world_from_body = Translation(0.0, 0.0, 1.2);
  spec.linear_velocity = Vec3(0.0, 0.0, -5.0);
  spec.material = MakeMaterial(0.5, 0.0);
  const BodyId box = AddBox(&world, spec);
  world
      .SetSettings([] {
        WorldSettings settings;
        settings.gravity = Vec3::Zero();  // the impact speed stays exactly 5 m/s
        return settings;
      }())
      .ok();
  double collision_impulse = 0.0;
  double lowest = 1e9;
  for (int step = 0; step < 240; ++step) {
    world.Step();
    for (const ContactReport& contact : world.TakeCollisionLog()) {
      if (contact.body_a == box || contact.body_b == box)
        collision_impulse += contact.normal_impulse;
    }
    lowest = std::min(lowest, world.GetPose(box).translation.z());
  }
  const Pose pose = world.GetPose(box);
  EXPECT_NEAR(collision_impulse, spec.mass * 5.0, 0.02 * spec.mass * 5.0);
  EXPECT_LT(pose.translation.head<2>().norm(), 1e-6);
  EXPECT_LT(world.GetAngularVelocity(box).norm(), 1e-6);
  EXPECT_LT(world.GetLinearVelocity(box).norm(), 1e-6);
  // Resting on the top face at z = 0.5: never deeper than the slop.
  EXPECT_GT(lowest, 1.0 - world.settings().solver.penetration_slop - 1e-6);
}

TEST(CollisionTest, CornerImpactMatchesBaraffImpulse) {
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  settings.sleep.enabled = false;
  World world(settings);
  const double e = 0.6;
  AddGround(&world, MakeMaterial(0.0, 0.0));
  BoxSpec spec;
  spec.size = Vec3(0.4, 0.6, 1.0);
  spec.mass = 3.0;
  spec.material = MakeMaterial(0.0, e);
  spec.world_from_body.rotation =
      Quat(Eigen::AngleAxisd(0.4, Vec3::UnitX()) * Eigen::AngleAxisd(0.3, Vec3::UnitY()));
  spec.linear_velocity = Vec3(0.3, -0.2, -2.0);
  spec.angular_velocity = Vec3(0.5, 1.0, -0.4);
  // Put the lowest corner half the contact tolerance above the ground:
  // touching.
  const Mat3 rotation = spec.world_from_body.rotation.toRotationMatrix();
  double lowest = 1e9;
  Vec3 lowest_corner_body = Vec3::Zero();
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 corner_body((corner & 1 ? 0.5 : -0.5) * spec.size.x(),
                           (corner & 2 ? 0.5 : -0.5) * spec.size.y(),
                           (corner & 4 ? 0.5 : -0.5) * spec.size.z());
    const double z = (rotation * corner_body).z();
    if (z < lowest) {
      lowest = z;
      lowest_corner_body = corner_body;
    }
  }
  spec.world_from_body.translation = Vec3(0, 0, -lowest + 0.5 * settings.solver.contact_tolerance);
  const BodyId box = AddBox(&world, spec);

  // By hand.
  const MassProperties mass_properties = BoxMassProperties(spec.mass / spec.size.prod(), spec.size);
  const Mat3 inverse_inertia_world =
      rotation * mass_properties.inertia_about_com.inverse() * rotation.transpose();
  const Vec3 r = rotation * lowest_corner_body;
  const Vec3 n = Vec3::UnitZ();
  const double v_r = n.dot(spec.linear_velocity + spec.angular_velocity.cross(r));
  ASSERT_LT(v_r, -0.1);
  const double j =
      -(1.0 + e) * v_r / (1.0 / spec.mass + n.dot((inverse_inertia_world * r.cross(n)).cross(r)));
  const Vec3 expected_momentum = spec.mass * spec.linear_velocity + j * n;
  const Vec3 expected_angular_momentum =
      inverse_inertia_world.inverse() * spec.angular_velocity + r.cross(j * n);

  world.Step();
  const Body& body = world.GetBody(box);
  EXPECT_LT((body.linear_momentum - expected_momentum).norm(), 1e-9 * expected_momentum.norm());
  EXPECT_LT((body.angular_momentum - expected_angular_momentum).norm(),
            1e-9 * expected_angular_momentum.norm());
  ASSERT_EQ(world.contacts().size(), 1u);
  EXPECT_EQ(world.contacts()[0].type, ContactType::kColliding);
  EXPECT_NEAR(world.contacts()[0].normal_impulse, j, 1e-9 * j);
  EXPECT_NEAR(world.contacts()[0].normal_velocity, v_r, 1e-12);
}

struct ConservationCase {
  double restitution;
  double friction;
};

class ConservationTest : public ::testing::TestWithParam<ConservationCase> {};

// Two boxes collide off-centre in zero gravity: linear and angular momentum
// (about the world origin) are conserved; kinetic energy is conserved for
// e = 1 without friction and never increases otherwise.
TEST_P(ConservationTest, OffCentreCollisionConservesMomentum) {
  const ConservationCase param = GetParam();
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  settings.sleep.enabled = false;
  World world(settings);
  BoxSpec a;
  a.size = Vec3(1.0, 0.8, 0.6);
  a.mass = 2.0;
  a.world_from_body = Translation(-1.5, 0.3, 0.2);
  a.world_from_body.rotation = Quat(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  a.linear_velocity = Vec3(3.0, 0.0, 0.1);
  a.angular_velocity = Vec3(0.0, 0.5, 1.0);
  a.material = MakeMaterial(param.friction, param.restitution);
  BoxSpec b = a;
  b.size = Vec3(0.5, 1.2, 0.9);
  b.mass = 1.0;
  b.world_from_body = Translation(1.5, -0.2, -0.1);
  b.world_from_body.rotation = Quat(Eigen::AngleAxisd(-0.7, Vec3(0, 1, 1).normalized()));
  b.linear_velocity = Vec3(-2.0, 0.1, 0.0);
  b.angular_velocity = Vec3(1.0, 0.0, -0.5);
  const std::vector<BodyId> ids = {AddBox(&world, a), AddBox(&world, b)};

  auto momentum = [&]() {
    Vec3 p = Vec3::Zero();
    for (BodyId id : ids) p += world.GetBody(id).linear_momentum;
    return p;
  };
  auto angular_momentum = [&]() {
    Vec3 l = Vec3::Zero();
    for (BodyId id : ids) {
      const Body& body = world.GetBody(id);
      l += body.position.cross(body.linear_momentum) + body.angular_momentum;
    }
    return l;
  };
  auto energy = [&]() {
    double total = 0.0;
    for (BodyId id : ids) total += KineticEnergy(world.GetBody(id));
    return total;
  };
  const Vec3 p0 = momentum();
  const Vec3 l0 = angular_momentum();
  const double e0 = energy();
  double previous_energy = e0;
  // Until the step after the impact: with e = 0 the boxes then stay in
  // contact, and the split impulse that later corrects their penetration moves
  // positions without momentum, which is not a collision's business.
  int steps_since_impact = -1;
  for (int step = 0; step < 240 && steps_since_impact < 1; ++step) {
    world.Step();
    if (steps_since_impact >= 0) ++steps_since_impact;
    for (const ContactReport& contact : world.contacts()) {
      if (contact.type == ContactType::kColliding && steps_since_impact < 0) steps_since_impact = 0;
    }
    EXPECT_LE(energy(), previous_energy * (1.0 + 1e-12)) << "step " << step;
    previous_energy = energy();
  }
  ASSERT_EQ(steps_since_impact, 1);
  EXPECT_LT((momentum() - p0).norm(), 1e-9 * p0.norm());
  EXPECT_LT((angular_momentum() - l0).norm(), 1e-9 * l0.norm());
  if (param.restitution == 1.0 && param.friction == 0.0) {
    EXPECT_NEAR(energy() / e0, 1.0, 1e-6) << "before " << e0 << " J, after " << energy() << " J";
  } else {
    EXPECT_LT(energy(), e0);
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, ConservationTest,
                         ::testing::Values(ConservationCase{1.0, 0.0}, ConservationCase{0.5, 0.0},
                                           ConservationCase{0.0, 0.0}, ConservationCase{0.8, 0.4}));

// Newton's cradle: five touching balls with e = 1, the first arriving at
// 1 m/s. Collisions propagate round by round, so the last ball leaves with
// (nearly) all the speed and the others stay (nearly) still.
TEST(CollisionTest, NewtonsCradleTransfersMomentumToTheLastBall) {
  WorldSettings settings;
  settings.gravity = Vec3::Zero();
  settings.sleep.enabled = false;
  World world(settings);
  const double radius = 0.1;
  std::vector<BodyId> balls;
  for (int i = 0; i < 5; ++i) {
    SphereSpec spec;
    spec.radius = radius;
    spec.world_from_body = Translation(2.0 * radius * i + 2e-4 * i, 0, 1);
    spec.material = MakeMaterial(0.0, 1.0);
    if (i == 0) {
      spec.world_from_body.translation.x() -= 0.05;
      spec.linear_velocity = Vec3(1.0, 0, 0);
    }
    balls.push_back(AddSphere(&world, spec));
  }
  for (int step = 0; step < 60; ++step) world.Step();
  const double last = world.GetLinearVelocity(balls[4]).x();
  EXPECT_GE(last, 0.95);
  for (int i = 0; i < 4; ++i) {
    EXPECT_LT(std::abs(world.GetLinearVelocity(balls[i]).x()), 0.05) << "ball " << i;
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics
