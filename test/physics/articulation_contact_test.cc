// Articulations in contact, against closed forms: a cart on a rail
// touching the ground keeps its speed, a box with a flap rests on the
// ground and rises out of it without launch speed, a gripper lifts a box
// without letting it slip, and a link pressing a stack is carried by the
// ground. Their impacts are link_impact_test.cc.
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
// 2 s, and a 100 kg link passed through it. The forces are held to
// `force_tolerance` of the weights.
void PressAStack(MotionSolverKind solver, int box_count, double force_tolerance = 1e-6) {
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
              force_tolerance * (box_count * kBoxMass + kLinkMass) * kG);
  EXPECT_NEAR(link_force, kLinkMass * kG, force_tolerance * kLinkMass * kG);
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

// Twelve boxes: an island of 12 bodies, within kMostLinkIslandBodies (16).
// Its rows between boxes are swept at most velocity_iterations (20) times,
// as the rigid solver sweeps its points, and then held, so the forces in
// the step carry what 20 sweeps leave on a 12-box stack: up to 7e-6 of the
// weights (4e-6 under the soft step); the heights hold as above. With the island
// limit at 4 bodies, an 8-box stack under the link collapsed to the
// ground within 2 s.
TEST(ArticulationContactTest, LinkPressingATallStackIsCarriedToTheGround) {
  PressAStack(MotionSolverKind::kExact, 12, 1e-5);
}

TEST(ArticulationContactTest, LinkPressingATallStackUnderTheSoftStepIsCarriedToTheGround) {
  PressAStack(MotionSolverKind::kSoftStep, 12, 1e-5);
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
