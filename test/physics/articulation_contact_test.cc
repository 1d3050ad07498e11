// Articulations in contact, against closed forms: a cart on a rail
// touching the ground keeps its speed, a box with a flap rests on the
// ground, rises out of it without launch speed, and bounces to e^2 h, a
// rigid ball bounces on a link to e^2 h, and a gripper lifts a box without
// letting it slip.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "articulation_fixtures.h"
#include "scene.h"

namespace rigid_body_sim::physics::testing {
namespace {

// A cart on a level rail (a prismatic joint along x from a fixed base)
// whose box touches the ground: the rail carries its weight, so the contact
// has no normal impulse to give and, by Coulomb's law, no friction either;
// the cart keeps its speed, x = v t. The contact's normal row and its first
// tangent (along y) move nothing, only the second tangent does, so the
// solver must still take the tangents as a pair: taken alone, the second
// one read the row after the last (found by AddressSanitizer in the soak).
TEST(ArticulationContactTest, CartOnALevelRailTouchingTheGroundKeepsItsSpeed) {
  World world = MakeWorld();
  AddGround(&world, MakeMaterial(0.8, 0.0));
  ArticulationDef def;
  def.fixed_base = true;
  def.world_from_base.translation = Vec3(0.0, 0.0, 0.0499);  // the box 0.1 mm into the ground
  LinkDef cart = Anchor();
  ShapeDef box;
  box.geometry = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3::Constant(0.1)));
  box.material = MakeMaterial(0.8, 0.0);
  cart.shapes.push_back(box);
  def.links = {Anchor(), cart};
  JointDef rail;
  rail.name = "rail";
  rail.type = JointType::kPrismatic;
  rail.axis = Vec3::UnitX();
  def.joints = {rail};
  const ArticulationId id = world.CreateArticulation(def).value();
  const double speed = 0.5;  // m/s
  ASSERT_TRUE(world.SetJointStates(id, {0.0}, {speed}).ok());
  const int steps = 240;
  for (int step = 0; step < steps; ++step) world.Step();
  const JointState state = world.GetJointStates(id)[0];
  EXPECT_NEAR(state.velocity, speed, 1e-12);
  EXPECT_NEAR(state.position, speed * steps * kDt, 1e-12);
  EXPECT_FALSE(world.contacts().empty());  // it did touch the ground throughout
}

// A floating two-link articulation (a box with a flap) dropped on the
// ground comes to rest on it at the box's half height, and a refused
// definition leaves the world unchanged.
TEST(ArticulationContactTest, FloatingArticulationRestsOnTheGround) {
  World world = MakeWorld();
  AddGround(&world, MakeMaterial(0.8, 0.0));
  ArticulationDef def = BoxWithFlap(0.5);
  def.joints[0].type = JointType::kRevolute;
  def.joints[0].lower = -0.1;
  def.joints[0].upper = 0.1;
  const std::size_t bodies_before = world.BodyCount();
  ArticulationDef bad = def;
  bad.joints[0].position = 0.5;  // outside [-0.1, 0.1]
  EXPECT_FALSE(world.CreateArticulation(bad).ok());
  EXPECT_EQ(world.BodyCount(), bodies_before);
  const ArticulationId id = world.CreateArticulation(def).value();
  for (int step = 0; step < 2 * 240; ++step) world.Step();
  const Pose base = world.GetPose(world.ArticulationLinks(id)[0]);
  EXPECT_NEAR(base.translation.z(), 0.1, 1e-3);
  EXPECT_LT(world.GetLinearVelocity(world.ArticulationLinks(id)[0]).norm(), 1e-2);
}

// Spawned 8 cm into the ground, the box is lifted out by the split
// impulse, which moves positions only. Without gravity it gains no speed
// at all (pushing through the real velocity, 0.2 of the depth per
// 1/240 s step, would launch it at 3.8 m/s); under gravity it stays below
// the speed that falling the depth gives, sqrt(2 g d) + 0.1 m/s as for
// rigid bodies (impact_test), never rises above its rest height, and
// rests there.
TEST(ArticulationContactTest, ArticulationSpawnedIntoTheGroundRisesWithoutLaunchSpeed) {
  constexpr double kDepth = 0.08;  // m
  for (const double gravity : {0.0, kG}) {
    WorldSettings settings;
    settings.time_step = kDt;
    settings.gravity = Vec3(0, 0, -gravity);
    World world(settings);
    AddGround(&world, MakeMaterial(0.8, 0.0));
    const ArticulationId id = world.CreateArticulation(BoxWithFlap(0.1 - kDepth)).value();
    const BodyId base = world.ArticulationLinks(id)[0];
    double fastest = 0.0;
    double highest = -kDepth;
    for (int step = 0; step < 2 * 240; ++step) {
      world.Step();
      fastest = std::max(fastest, world.GetLinearVelocity(base).norm());
      highest = std::max(highest, world.GetPose(base).translation.z());
    }
    if (gravity == 0.0) {
      EXPECT_LT(fastest, 1e-9);
    } else {
      EXPECT_LT(fastest, std::sqrt(2.0 * gravity * kDepth) + 0.1);
    }
    EXPECT_LT(highest, 0.1 + 1e-3) << "gravity " << gravity;
    // Lifted to within the slop of touching.
    EXPECT_NEAR(world.GetPose(base).translation.z(), 0.1, 1e-3) << "gravity " << gravity;
  }
}

// A bouncing articulation: the box with its flap, e = 0.5, dropped from
// h = 0.2 m, rises to e^2 h after its first impact, as a rigid box does
// (collision_test's BounceTest), and then comes to rest on its face. Before
// the restitution pass (BounceLinkContacts) the row that stopped it where it
// touched took its speed, and it rose to 0.012 m instead of 0.05. Resting
// on the ground, each step's free motion closes its contact at g dt =
// 0.041 m/s, above the collision threshold; classified by that speed
// instead of the speed the step starts with, the box hopped at
// e g dt every step and never rested.
TEST(ArticulationContactTest, BouncingArticulationRisesToRestitutionSquaredAndRests) {
  constexpr double kDrop = 0.2;         // m, from the base's rest height
  constexpr double kRestitution = 0.5;  // the box's; the ground's is 0
  World world = MakeWorld();
  AddGround(&world, MakeMaterial(0.8, 0.0));
  ArticulationDef def = BoxWithFlap(0.1 + kDrop);
  def.links[0].shapes[0].material = MakeMaterial(0.8, kRestitution);
  def.joints[0].type = JointType::kRevolute;  // the flap comes to rest at a limit
  def.joints[0].lower = -0.1;
  def.joints[0].upper = 0.1;
  const ArticulationId id = world.CreateArticulation(def).value();
  const BodyId base = world.ArticulationLinks(id)[0];
  bool rising = false;
  double apex = 0.0;
  for (int step = 0; step < 240 && apex == 0.0; ++step) {
    const double before = world.GetLinearVelocity(base).z();
    world.Step();
    const double after = world.GetLinearVelocity(base).z();
    rising = rising || (before < 0.0 && after > 0.0);
    if (rising && after <= 0.0) apex = world.GetPose(base).translation.z() - 0.1;
  }
  std::printf("first apex %.5f m, e^2 h = %.5f m\n", apex, kRestitution * kRestitution * kDrop);
  // It leaves the ground at the time it touches, with e times the speed it
  // struck with. The apex is sampled at steps, within g dt^2 of the true
  // one, and the velocity-level steps that meet the ground (q + dt u+)
  // stand up to g dt^2 / 2 of height each, before and after the impact.
  // Bounced at the end of the step instead, it rose e v- dt lower (4 mm).
  EXPECT_NEAR(apex, kRestitution * kRestitution * kDrop, 2.0 * kG * kDt * kDt);
  for (int step = 0; step < 3 * 240; ++step) world.Step();
  EXPECT_NEAR(world.GetPose(base).translation.z(), 0.1, 1e-3);
  for (const BodyId link : world.ArticulationLinks(id)) {
    EXPECT_LT(world.GetLinearVelocity(link).norm(), 1e-6);
    EXPECT_LT(world.GetAngularVelocity(link).norm(), 1e-6);
  }
}

// A rigid link on a hinge about z (gravity along the axis gives it no
// torque) swings its 1 cm ball into the face y = 0 of a static box,
// e = 0.5, no friction. The ball touches at theta_c = -asin(r / L), at
// t_c = 5.37 steps: the impact step must end at
// theta_c - e omega (t - t_c), the rebound resolved at t_c, not at the end
// of the step (a link stopped there and bounced lags e omega 0.63 dt =
// 4e-3 rad at 3 m/s), and leave at -e omega to 1e-6 relative. The joint
// moves on q + t u within a step, while the gap follows the sine of q: a
// time found from the gap's rate at the start of the step was late, 2e-7
// rad after the rebound at 3 m/s and 6.6e-5 rad at 30 m/s; found from the
// shapes' gap on the path it is within 1e-10 m of the touch.
void StrikeAStaticBox(double impact_speed, double box_thickness) {
  constexpr double kLength = 1.0;       // m, hinge to ball centre
  constexpr double kRadius = 0.01;      // m
  constexpr double kRestitution = 0.5;  // both materials
  constexpr double kStepsToImpact = 5.37;
  const double contact_angle = -std::asin(kRadius / kLength);
  const double omega = impact_speed / (kLength * std::cos(contact_angle));
  const double start_angle = contact_angle - omega * kStepsToImpact * kDt;
  World world = MakeWorld();
  BoxSpec wall;
  wall.size = Vec3(0.2, box_thickness, 0.2);
  wall.world_from_body = Translation(kLength, 0.5 * box_thickness, 0.0);
  wall.is_static = true;
  wall.material = MakeMaterial(0.0, kRestitution);
  AddBox(&world, wall);
  ArticulationDef def;
  def.fixed_base = true;
  LinkDef arm;
  arm.mass_properties.mass = 1.0;
  arm.mass_properties.center_of_mass = Vec3(kLength, 0, 0);
  arm.mass_properties.inertia_about_com = Mat3::Identity() * 1e-4;
  ShapeDef ball;
  ball.geometry = Sphere{kRadius};
  ball.body_from_shape.translation = Vec3(kLength, 0, 0);
  ball.material = MakeMaterial(0.0, kRestitution);
  arm.shapes.push_back(ball);
  def.links = {Anchor(), arm};
  JointDef hinge = Hinge(1, 0.0, start_angle);
  hinge.axis = Vec3::UnitZ();
  hinge.velocity = omega;
  def.joints = {hinge};
  const ArticulationId id = world.CreateArticulation(def).value();
  int steps = 0;
  while (steps < 20 && world.GetJointStates(id)[0].velocity > 0.0) {
    world.Step();
    ++steps;
  }
  ASSERT_EQ(steps, 6) << "the ball should strike within the sixth step";
  const JointState after = world.GetJointStates(id)[0];
  const double contact_time = kStepsToImpact * kDt;
  const double expected = contact_angle - kRestitution * omega * (steps * kDt - contact_time);
  std::printf(
      "%.0f m/s: end of the impact step %.12f rad, exact %.12f rad; omega+ %.12f, -e omega "
      "%.12f\n",
      impact_speed, after.position, expected, after.velocity, -kRestitution * omega);
  EXPECT_NEAR(after.position, expected, 1e-9);
  EXPECT_NEAR(after.velocity / (-kRestitution * omega), 1.0, 1e-6);
  // Away from the box it swings back freely: theta falls at e omega.
  world.Step();
  EXPECT_NEAR(world.GetJointStates(id)[0].position, expected - kRestitution * omega * kDt, 1e-9);
}

TEST(ArticulationContactTest, HingedLinkStrikesAStaticBoxAtTheContactTimeAndRebounds) {
  StrikeAStaticBox(3.0, 0.2);
}

// 30 m/s, 12.5 cm a step, against a 1 cm plate: the path's samples keep the
// ball from passing it, and the time is as exact.
TEST(ArticulationContactTest, FastHingedLinkStrikesAThinPlateAtTheContactTime) {
  StrikeAStaticBox(30.0, 0.01);
}

// A rigid ball, e = 0.8, dropped h = 0.5 m onto the box of a fixed-base
// box-with-flap bounces to e^2 h, then e^4 h: the restitution pass gives
// it e v- and leaves its drift over the step to where it touches, so it
// rises at most one step late (e v- dt lower) and never higher. Without
// the pass the row that stopped it took its speed (0.012 m of 0.05 for the
// box above); with the bounced speed drifting over the whole step it rose
// 13 mm too high.
TEST(ArticulationContactTest, RigidBallBouncesOnALinkToRestitutionSquared) {
  constexpr double kDrop = 0.5;         // m, from touching
  constexpr double kRestitution = 0.8;  // the ball's; the link's is 0
  constexpr double kRadius = 0.05;      // m
  World world = MakeWorld();
  ArticulationDef def = BoxWithFlap(0.0);
  def.fixed_base = true;
  world.CreateArticulation(def).value();
  SphereSpec spec;
  spec.radius = kRadius;
  spec.world_from_body = Translation(0.03, 0.02, 0.1 + kRadius + kDrop);
  spec.material = MakeMaterial(0.5, kRestitution);
  const BodyId ball = AddSphere(&world, spec);
  double height = kDrop;
  for (int bounce = 0; bounce < 2; ++bounce) {
    const double impact_speed = std::sqrt(2.0 * kG * height);
    double apex = -1.0;
    for (int step = 0; step < 2 * 240 && apex < 0.0; ++step) {
      const double before = world.GetLinearVelocity(ball).z();
      world.Step();
      if (before > 0.0 && world.GetLinearVelocity(ball).z() <= 0.0) {
        apex = world.GetPose(ball).translation.z() - 0.1 - kRadius;
      }
    }
    const double expected = kRestitution * kRestitution * height;
    std::printf("bounce %d: apex %.5f m, e^2 h = %.5f m\n", bounce + 1, apex, expected);
    EXPECT_LT(apex, expected + kG * kDt * kDt);
    EXPECT_GT(apex, expected - kRestitution * impact_speed * kDt - kG * kDt * kDt);
    height = apex;
  }
}

// A ball spawned 1 cm into a flap that a velocity motor holds at 0 rad/s
// (effort 100 N m), without gravity. The split impulse pushes the ball out;
// the motor's row holds in the correction as in the velocity solve, so the
// flap does not turn (a 1 kg ball pushed out at 0.2 of its depth per step
// needs a small part of the motor's 100 N m). Without the joint's rows in
// the correction, the flap, an eighth of the ball's mass, was pushed aside.
TEST(ArticulationContactTest, SplitImpulseDoesNotTurnAJointItsMotorHolds) {
  constexpr double kRadius = 0.05;  // m
  constexpr double kDepth = 0.01;   // m, into the flap's +x face
  WorldSettings settings;
  settings.time_step = kDt;
  settings.gravity = Vec3::Zero();
  World world(settings);
  ArticulationDef def = BoxWithFlap(0.0);
  def.fixed_base = true;
  def.joints[0].effort_limit = 100.0;
  ShapeDef flap;  // the flap's 5 cm cube, its centre 5 cm above the hinge
  flap.geometry =
      std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3(0.05, 0.05, 0.05)));
  flap.body_from_shape.translation = Vec3(0, 0, 0.05);
  flap.material = MakeMaterial(0.0, 0.0);
  def.links[1].shapes.push_back(flap);
  const ArticulationId arm = world.CreateArticulation(def).value();
  ASSERT_TRUE(world.SetJointCommand(arm, 0, {JointCommandMode::kVelocity, 0.0, 0.0, 0.0}).ok());
  SphereSpec spec;
  spec.radius = kRadius;
  spec.world_from_body = Translation(0.025 + kRadius - kDepth, 0.0, 0.15);
  spec.material = MakeMaterial(0.0, 0.0);
  const BodyId ball = AddSphere(&world, spec);
  for (int step = 0; step < 240; ++step) world.Step();
  EXPECT_NEAR(world.GetJointStates(arm)[0].position, 0.0, 1e-9);
  // Pushed out to within the slop, with no launch speed: the split impulse
  // moves positions only.
  EXPECT_GT(world.GetPose(ball).translation.x(),
            0.025 + kRadius - settings.solver.penetration_slop - 1e-6);
  EXPECT_LT(world.GetLinearVelocity(ball).norm(), 1e-9);
}

LinkDef BoxLink(double mass, const Vec3& size, double friction) {
  LinkDef link;
  link.mass_properties = BoxMassProperties(mass / size.prod(), size);
  ShapeDef shape;
  shape.geometry = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(size));
  shape.material = MakeMaterial(friction, 0.0);
  link.shapes.push_back(shape);
  return link;
}

// A parallel gripper on a lift: two fingers squeeze a 0.2 kg box with 20 N
// each (mu = 1), the lift raises it 0.2 m in 1 s and holds it 5 s. The box
// rises with the hand and slips less than 5 mm relative to it.
// Both solvers: the rigid box's contacts are the solver's, the fingers'
// the articulations' joint-space solve.
void LiftBoxInGripper(MotionSolverKind solver) {
  World world = MakeWorld(solver);
  AddGround(&world, MakeMaterial(1.0, 0.0));
  BoxSpec spec;
  spec.size = Vec3(0.05, 0.05, 0.05);
  spec.mass = 0.2;
  spec.world_from_body = Translation(0, 0, 0.025);
  spec.material = MakeMaterial(1.0, 0.0);
  const BodyId box = AddBox(&world, spec);
  ArticulationDef def;
  def.fixed_base = true;
  def.world_from_base = Translation(0, 0, 0.1);
  def.links = {Anchor(), BoxLink(1.0, Vec3(0.1, 0.2, 0.02), 1.0),
               BoxLink(0.1, Vec3(0.04, 0.01, 0.06), 1.0),
               BoxLink(0.1, Vec3(0.04, 0.01, 0.06), 1.0)};
  // The lift slides along z; each finger hangs 0.06 m below the carriage and
  // closes toward y = 0 along its axis.
  def.joints = {Slider("lift", 0, 1, Vec3::Zero(), Vec3::UnitZ()),
                Slider("left", 1, 2, Vec3(0, 0.032, -0.06), -Vec3::UnitY()),
                Slider("right", 1, 3, Vec3(0, -0.032, -0.06), Vec3::UnitY())};
  const ArticulationId hand = world.CreateArticulation(def).value();
  JointCommand hold_lift;
  hold_lift.mode = JointCommandMode::kPosition;
  ASSERT_TRUE(world.SetJointCommand(hand, 0, hold_lift).ok());
  JointCommand squeeze;
  squeeze.mode = JointCommandMode::kEffort;
  squeeze.effort = 20.0;
  ASSERT_TRUE(world.SetJointCommand(hand, 1, squeeze).ok());
  ASSERT_TRUE(world.SetJointCommand(hand, 2, squeeze).ok());
  for (int step = 0; step < 120; ++step) world.Step();
  const int lift_steps = 240;
  for (int step = 1; step <= lift_steps; ++step) {
    hold_lift.position = 0.2 * step / lift_steps;
    hold_lift.velocity = 0.2;
    ASSERT_TRUE(world.SetJointCommand(hand, 0, hold_lift).ok());
    world.Step();
  }
  hold_lift.velocity = 0.0;
  ASSERT_TRUE(world.SetJointCommand(hand, 0, hold_lift).ok());
  const BodyId carriage = world.ArticulationLinks(hand)[1];
  const double start_offset =
      world.GetPose(box).translation.z() - world.GetPose(carriage).translation.z();
  for (int step = 0; step < 5 * 240; ++step) world.Step();
  const double end_offset =
      world.GetPose(box).translation.z() - world.GetPose(carriage).translation.z();
  EXPECT_NEAR(world.GetPose(box).translation.z(), 0.025 + 0.2, 5e-3);
  EXPECT_LT(std::abs(end_offset - start_offset), 5e-3);
}

TEST(ArticulationContactTest, GripperLiftsABoxWithoutLettingItSlip) {
  LiftBoxInGripper(MotionSolverKind::kExact);
}

TEST(ArticulationContactTest, GripperLiftsABoxWithoutLettingItSlipUnderTheSoftStep) {
  LiftBoxInGripper(MotionSolverKind::kSoftStep);
}

// A gripper of two fingers on prismatic joints holds a 5 cm, 0.1 kg box
// still for 3 s (six times time_to_sleep), then opens. Sleep follows the
// link: while held the box stays awake, and let go it falls freely,
// ~g t^2 / 2, to the ground and rests there, instead of sleeping where it
// was held (its quiet time had counted on through the hold, and it fell
// asleep in mid-air the step the fingers opened).
TEST(ArticulationContactTest, BoxLetGoByAGripperFallsInsteadOfSleepingInTheAir) {
  World world = MakeWorld();
  AddGround(&world, MakeMaterial(0.8, 0.0));
  ArticulationDef def;
  def.fixed_base = true;
  def.world_from_base = Translation(0, 0, 0.5);
  def.links.push_back(Anchor());
  const Vec3 pad_size(0.01, 0.04, 0.06);
  for (const int side : {-1, 1}) {
    LinkDef finger;
    finger.mass_properties = BoxMassProperties(1000.0, pad_size);
    ShapeDef pad;
    pad.geometry = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(pad_size));
    pad.material = MakeMaterial(1.0, 0.0);
    finger.shapes.push_back(pad);
    def.links.push_back(finger);
    JointDef slider = Slider(side < 0 ? "left" : "right", 0, static_cast<int>(def.links.size()) - 1,
                             Vec3(side * 0.03, 0, 0), Vec3(side, 0, 0));
    slider.lower = -0.1;
    slider.upper = 0.1;
    slider.effort_limit = 100.0;
    def.joints.push_back(slider);
  }
  const Result<ArticulationId> gripper = world.CreateArticulation(def);
  ASSERT_TRUE(gripper.ok()) << gripper.message();
  BoxSpec spec;
  spec.size = Vec3(0.05, 0.05, 0.05);
  spec.mass = 0.1;
  spec.world_from_body = Translation(0, 0, 0.5);
  spec.material = MakeMaterial(1.0, 0.0);
  const BodyId box = AddBox(&world, spec);
  const auto command_both = [&](double position) {
    JointCommand command;
    command.mode = JointCommandMode::kPosition;
    command.position = position;
    for (const int joint : {0, 1})
      ASSERT_TRUE(world.SetJointCommand(*gripper, joint, command).ok());
  };
  command_both(-0.01);  // 1 cm into the box: a firm squeeze
  for (int step = 0; step < 3 * 240; ++step) world.Step();
  const double held_z = world.GetPose(box).translation.z();
  EXPECT_NEAR(held_z, 0.5, 1e-3);
  EXPECT_TRUE(world.GetBody(box).awake);
  command_both(0.05);
  double released_at = -1.0;
  for (int step = 0; step < 240; ++step) {
    world.Step();
    const Body& body = world.GetBody(box);
    if (released_at < 0.0 && body.linear_velocity.z() < -0.01) released_at = world.time();
    // Never asleep above the ground while it falls.
    if (world.GetPose(box).translation.z() > 0.03) {
      EXPECT_TRUE(body.awake) << world.time();
    }
  }
  ASSERT_GT(released_at, 0.0);
  // 0.475 m of free fall takes sqrt(2 h / g) = 0.311 s: within the second
  // after release it is on the ground, at half its size, at rest.
  EXPECT_NEAR(world.GetPose(box).translation.z(), 0.025, 1e-3);
  EXPECT_LT(world.GetBody(box).linear_velocity.norm(), 0.05);
}

// A 10 kg link on a vertical slider rests on a stack of 1 kg, 0.2 m boxes
// on the ground: one contact problem for the stack's island, links and
// bodies together. The ground carries every weight, (n + 10) g, each box
// stays at its height within the slop of each contact under it, and the
// link's contact carries its own weight. Solved
// apart (the boxes' contacts first, then the link's with the boxes' solved
// velocities), the link's push sank a single box 9.4 cm into the ground in
// 2 s, and a 100 kg link passed through it.
void PressAStack(MotionSolverKind solver, int box_count) {
  constexpr double kBoxMass = 1.0;    // kg
  constexpr double kLinkMass = 10.0;  // kg
  constexpr double kBoxSize = 0.2;    // m
  constexpr double kLinkSize = 0.1;   // m
  World world = MakeWorld(solver);
  const BodyId ground = AddGround(&world, MakeMaterial(0.5, 0.0));
  std::vector<BodyId> boxes;
  for (int i = 0; i < box_count; ++i) {
    BoxSpec spec;
    spec.size = Vec3::Constant(kBoxSize);
    spec.mass = kBoxMass;
    spec.world_from_body = Translation(0, 0, (i + 0.5) * kBoxSize);
    spec.material = MakeMaterial(0.5, 0.0);
    boxes.push_back(AddBox(&world, spec));
  }
  const double link_height = box_count * kBoxSize + 0.5 * kLinkSize;
  ArticulationDef def;
  def.fixed_base = true;
  def.world_from_base = Translation(0, 0, link_height);
  def.links.push_back(Anchor());
  def.links.push_back(BoxLink(kLinkMass, Vec3::Constant(kLinkSize), 0.5));
  def.joints.push_back(Slider("press", 0, 1, Vec3::Zero(), Vec3::UnitZ()));
  const ArticulationId press = world.CreateArticulation(def).value();
  const BodyId link = world.ArticulationLinks(press)[1];
  for (int step = 0; step < 2 * 240; ++step) world.Step();
  double ground_force = 0.0;
  double link_force = 0.0;
  for (const ContactReport& contact : world.contacts()) {
    if (contact.body_a.index == ground.index || contact.body_b.index == ground.index)
      ground_force += contact.normal_force;
    if (contact.body_a.index == link.index || contact.body_b.index == link.index)
      link_force += contact.normal_force;
  }
  std::printf("%d boxes: top box at %.7f m (%.7f), link at %.7f m; ground %.6f N, link %.6f N\n",
              box_count, world.GetPose(boxes.back()).translation.z(), (box_count - 0.5) * kBoxSize,
              world.GetPose(link).translation.z(), ground_force, link_force);
  // Each contact below a box may sink it by the slop, as the rigid solver
  // allows (the split impulse lifts only what is deeper), and nothing
  // launches it.
  const double slop = WorldSettings().solver.penetration_slop;
  for (int i = 0; i < box_count; ++i) {
    const double z = world.GetPose(boxes[i]).translation.z();
    EXPECT_GT(z, (i + 0.5) * kBoxSize - (i + 1) * slop - 1e-7) << i;
    EXPECT_LT(z, (i + 0.5) * kBoxSize + 1e-7) << i;
  }
  const double link_z = world.GetPose(link).translation.z();
  EXPECT_GT(link_z, link_height - (box_count + 1) * slop - 1e-7);
  EXPECT_LT(link_z, link_height + 1e-7);
  EXPECT_NEAR(ground_force, (box_count * kBoxMass + kLinkMass) * kG,
              1e-6 * (box_count * kBoxMass + kLinkMass) * kG);
  EXPECT_NEAR(link_force, kLinkMass * kG, 1e-6 * kLinkMass * kG);
}

TEST(ArticulationContactTest, LinkPressingABoxOnTheGroundIsCarriedByTheGround) {
  PressAStack(MotionSolverKind::kExact, 1);
}

TEST(ArticulationContactTest, LinkPressingAStackIsCarriedThroughItToTheGround) {
  PressAStack(MotionSolverKind::kExact, 3);
}

TEST(ArticulationContactTest, LinkPressingAStackUnderTheSoftStepIsCarriedToTheGround) {
  PressAStack(MotionSolverKind::kSoftStep, 3);
}

// A 0.2 m box on two sliding joints (x, then z through a link without
// shape) above the 0.2 m box of its fixed base: two links not joined to
// each other. Self-colliding, the top box falls 0.3 m and rests on the base
// at z = 0.2 m; otherwise the broad phase never pairs them (one collision
// group) and it falls freely: z = 0.5 - g t^2 / 2 after 1 s, to rounding.
TEST(ArticulationContactTest, OnlyASelfCollidingArticulationTouchesItself) {
  for (const bool self_collide : {true, false}) {
    SCOPED_TRACE(self_collide);
    World world = MakeWorld();
    ArticulationDef def;
    def.fixed_base = true;
    def.self_collide = self_collide;
    def.links.push_back(BoxLink(1.0, Vec3::Constant(0.2), 0.5));
    LinkDef slider;
    slider.mass_properties.mass = 1.0;
    slider.mass_properties.inertia_about_com = Mat3::Identity() * 0.01;
    def.links.push_back(slider);
    def.links.push_back(BoxLink(1.0, Vec3::Constant(0.2), 0.5));
    for (int i = 1; i <= 2; ++i) {
      JointDef joint;
      joint.name = "slide" + std::to_string(i);
      joint.type = JointType::kPrismatic;
      joint.parent_link = i - 1;
      joint.child_link = i;
      joint.axis = i == 1 ? Vec3::UnitX() : Vec3::UnitZ();
      if (i == 2) joint.parent_from_joint.translation = Vec3(0, 0, 0.5);
      def.joints.push_back(joint);
    }
    const ArticulationId id = world.CreateArticulation(def).value();
    for (int step = 0; step < 240; ++step) world.Step();
    const double z = world.GetPose(world.ArticulationLinks(id)[2]).translation.z();
    if (self_collide) {
      EXPECT_NEAR(z, 0.2, 2e-3);
    } else {
      EXPECT_NEAR(z, 0.5 - 0.5 * kG, 1e-9);
    }
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics::testing
