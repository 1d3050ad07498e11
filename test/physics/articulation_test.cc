// Articulations against closed forms and conservation laws: the pendulum's
// elliptic-integral period, the double pendulum's energy, a tilted prismatic
// joint's acceleration, an inelastic joint limit, a 30-link chain with a
// heavy tip that may not stretch, the servo's and the motor's steady states,
// and a link resting on the ground.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "scene.h"

namespace rigid_body_sim::physics::testing {
namespace {

constexpr double kG = 9.81;
constexpr double kDt = 1.0 / 240.0;

// A slender rod of mass m and length l along -z of its link frame, with a
// sphere of radius `radius` at its end for contact.
LinkDef Rod(double mass, double length, double radius = 0.0) {
  LinkDef link;
  link.mass_properties.mass = mass;
  link.mass_properties.center_of_mass = Vec3(0, 0, -length);
  const double i = mass * 1e-4;  // nearly a point mass at the end
  link.mass_properties.inertia_about_com = Mat3::Identity() * i;
  if (radius > 0.0) {
    ShapeDef shape;
    shape.geometry = Sphere{radius};
    shape.body_from_shape.translation = Vec3(0, 0, -length);
    link.shapes.push_back(shape);
  }
  return link;
}

LinkDef Anchor() {
  LinkDef link;
  link.mass_properties.mass = 1.0;
  link.mass_properties.inertia_about_com = Mat3::Identity() * 0.01;
  return link;
}

// Joint k: revolute about y, at the end of the parent rod of `length`
// (at the base's origin for the first).
JointDef Hinge(int child, double parent_length, double position) {
  JointDef joint;
  joint.name = "j" + std::to_string(child);
  joint.type = JointType::kContinuous;
  joint.parent_link = child - 1;
  joint.child_link = child;
  joint.parent_from_joint.translation = Vec3(0, 0, -parent_length);
  joint.axis = Vec3::UnitY();
  joint.position = position;
  return joint;
}

World MakeWorld() {
  WorldSettings settings;
  settings.time_step = kDt;
  settings.gravity = Vec3(0, 0, -kG);
  return World(settings);
}

// K(k) = pi / (2 AGM(1, sqrt(1 - k^2))) (Abramowitz and Stegun 1964,
// 17.6).
double EllipticK(double k) {
  double a = 1.0;
  double b = std::sqrt(1.0 - k * k);
  for (int i = 0; i < 40; ++i) {
    const double next = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = next;
  }
  return kPi / (2.0 * a);
}

// The pendulum's period T = 4 sqrt(I_p / (m g l)) K(sin(theta0 / 2)),
// measured over ten periods from the upward zero crossings of the angle,
// each placed by linear interpolation between steps.
TEST(ArticulationTest, PendulumPeriodMatchesTheEllipticIntegral) {
  for (const double amplitude_degrees : {10.0, 45.0, 90.0}) {
    SCOPED_TRACE(amplitude_degrees);
    World world = MakeWorld();
    const double mass = 1.0;
    const double length = 1.0;
    ArticulationDef def;
    def.fixed_base = true;
    def.links = {Anchor(), Rod(mass, length)};
    const double amplitude = amplitude_degrees * kPi / 180.0;
    def.joints = {Hinge(1, 0.0, amplitude)};
    const ArticulationId pendulum = world.CreateArticulation(def).value();
    const double inertia = mass * 1e-4 + mass * length * length;
    const double expected =
        4.0 * std::sqrt(inertia / (mass * kG * length)) * EllipticK(std::sin(0.5 * amplitude));
    std::vector<double> crossings;
    double previous = amplitude;
    for (int step = 1; crossings.size() < 11 && step < 100000; ++step) {
      world.Step();
      const double angle = world.GetJointStates(pendulum)[0].position;
      if (previous < 0.0 && angle >= 0.0) {
        crossings.push_back((step - 1 + previous / (previous - angle)) * kDt);
      }
      previous = angle;
    }
    ASSERT_EQ(crossings.size(), 11u);
    const double period = (crossings.back() - crossings.front()) / 10.0;
    EXPECT_NEAR(period / expected, 1.0, 1e-5);
  }
}

double TotalEnergy(const World& world, ArticulationId id) {
  double energy = 0.0;
  for (const BodyId link : world.ArticulationLinks(id)) {
    const Body& body = world.GetBody(link);
    energy += KineticEnergy(body) + body.mass * kG * body.position.z();
  }
  return energy;
}

// Released from horizontal, the undamped double pendulum is chaotic; its
// energy is conserved. The drift is measured as a share of the energy above
// the hanging rest.
TEST(ArticulationTest, DoublePendulumConservesEnergy) {
  World world = MakeWorld();
  ArticulationDef def;
  def.fixed_base = true;
  def.links = {Anchor(), Rod(1.0, 1.0), Rod(1.0, 1.0)};
  def.joints = {Hinge(1, 0.0, kPi / 2), Hinge(2, 1.0, 0.0)};
  const ArticulationId pendulum = world.CreateArticulation(def).value();
  const double rest = -kG * (1.0 + 2.0);  // both masses hanging: z = -1 and -2
  const double start = TotalEnergy(world, pendulum);
  double worst = 0.0;
  for (int step = 0; step < 20 * 240; ++step) {
    world.Step();
    worst = std::max(worst, std::abs(TotalEnergy(world, pendulum) - start));
  }
  EXPECT_LT(worst / (start - rest), 2e-3);
}

// A carriage on a prismatic joint tilted theta from the vertical
// accelerates at g cos(theta) along it.
TEST(ArticulationTest, TiltedPrismaticAcceleratesAtGCosTheta) {
  for (const double theta : {0.0, 0.5, 1.2}) {
    SCOPED_TRACE(theta);
    World world = MakeWorld();
    ArticulationDef def;
    def.fixed_base = true;
    LinkDef carriage = Anchor();
    carriage.mass_properties.mass = 3.0;
    def.links = {Anchor(), carriage};
    JointDef slide;
    slide.name = "slide";
    slide.type = JointType::kPrismatic;
    slide.axis = Vec3(std::sin(theta), 0.0, -std::cos(theta));
    def.joints = {slide};
    const ArticulationId id = world.CreateArticulation(def).value();
    const int steps = 240;
    for (int step = 0; step < steps; ++step) world.Step();
    const double t = steps * kDt;
    const double expected = 0.5 * kG * std::cos(theta) * t * t;
    const JointState state = world.GetJointStates(id)[0];
    EXPECT_NEAR(state.position / expected, 1.0, 1e-4);
    EXPECT_NEAR(state.velocity / (kG * std::cos(theta) * t), 1.0, 1e-4);
  }
}

// A cart on a level rail (a prismatic joint along x from a fixed base)
// whose box touches the ground: the rail carries its weight, so the contact
// has no normal impulse to give and, by Coulomb's law, no friction either;
// the cart keeps its speed, x = v t. The contact's normal row and its first
// tangent (along y) move nothing, only the second tangent does, so the
// solver must still take the tangents as a pair: taken alone, the second
// one read the row after the last (found by AddressSanitizer in the soak).
TEST(ArticulationTest, CartOnALevelRailTouchingTheGroundKeepsItsSpeed) {
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

// Released 90 degrees from its lower limit, with gravity still pressing it
// there, the arm stops at the limit: no overshoot beyond 1 mrad, no bounce.
TEST(ArticulationTest, JointLimitStopsWithoutOvershootOrBounce) {
  World world = MakeWorld();
  ArticulationDef def;
  def.fixed_base = true;
  def.links = {Anchor(), Rod(1.0, 1.0)};
  // The rod hangs at angle 0; gravity turns it toward 0 from either side.
  // The lower limit at 0.3 rad is reached moving down, and gravity still
  // presses the rod against it there.
  constexpr double kLower = 0.3;
  JointDef hinge = Hinge(1, 0.0, kLower + kPi / 2);
  hinge.type = JointType::kRevolute;
  hinge.lower = kLower;
  hinge.upper = kLower + kPi / 2;
  def.joints = {hinge};
  const ArticulationId id = world.CreateArticulation(def).value();
  double lowest = kPi;
  bool reached = false;
  double highest_after = -kPi;
  for (int step = 0; step < 3 * 240; ++step) {
    world.Step();
    const double angle = world.GetJointStates(id)[0].position;
    lowest = std::min(lowest, angle);
    if (angle < kLower + 1e-3) reached = true;
    if (reached) highest_after = std::max(highest_after, angle);
  }
  ASSERT_TRUE(reached);
  EXPECT_GT(lowest, kLower - 1e-3);
  EXPECT_LT(highest_after, kLower + 1e-3);
}

double AnchorSeparation(const World& world, ArticulationId id, const ArticulationDef& def) {
  const std::vector<BodyId> links = world.ArticulationLinks(id);
  double worst = 0.0;
  for (const JointDef& joint : def.joints) {
    const Vec3 from_parent =
        world.GetPose(links[joint.parent_link]) * joint.parent_from_joint.translation;
    const Vec3 child_origin = world.GetPose(links[joint.child_link]).translation;
    worst = std::max(worst, (from_parent - child_origin).norm());
  }
  return worst;
}

// 30 links of 0.1 kg and a 100 kg tip (1000:1), released horizontal and
// swinging for 10 s: no joint separates, and energy stays (RK4 loses a
// little; it may not gain).
TEST(ArticulationTest, HeavyTippedChainNeverStretches) {
  World world = MakeWorld();
  ArticulationDef def;
  def.fixed_base = true;
  def.links.push_back(Anchor());
  const int count = 30;
  for (int i = 1; i <= count; ++i) {
    def.links.push_back(Rod(i == count ? 100.0 : 0.1, 0.1));
    def.joints.push_back(Hinge(i, i == 1 ? 0.0 : 0.1, i == 1 ? kPi / 2 : 0.0));
  }
  const ArticulationId chain = world.CreateArticulation(def).value();
  const double start = TotalEnergy(world, chain);
  double worst = 0.0;
  for (int step = 0; step < 10 * 240; ++step) {
    world.Step();
    worst = std::max(worst, AnchorSeparation(world, chain, def));
  }
  EXPECT_LT(worst, 1e-6);
  const double end = TotalEnergy(world, chain);
  ASSERT_TRUE(std::isfinite(end));
  EXPECT_LT(end, start + 1e-3 * std::abs(start));
}

// A position servo holds a horizontal arm against gravity with the spring's
// steady error tau / k; a velocity motor turns at its commanded speed.
TEST(ArticulationTest, ServoHoldsWithinTauOverKAndMotorKeepsItsSpeed) {
  World world = MakeWorld();
  ArticulationDef def;
  def.fixed_base = true;
  def.links = {Anchor(), Rod(2.0, 0.5)};
  JointDef hinge = Hinge(1, 0.0, kPi / 2);
  hinge.effort_limit = 100.0;
  def.joints = {hinge};
  const ArticulationId id = world.CreateArticulation(def).value();
  ServoGains gains;
  ASSERT_TRUE(world.SetServoGains(id, gains).ok());
  JointCommand hold;
  hold.mode = JointCommandMode::kPosition;
  hold.position = kPi / 2;
  ASSERT_TRUE(world.SetJointCommand(id, 0, hold).ok());
  for (int step = 0; step < 5 * 240; ++step) world.Step();
  const double gravity_torque = 2.0 * kG * 0.5;  // horizontal: full lever arm
  const JointState held = world.GetJointStates(id)[0];
  EXPECT_NEAR(held.position, kPi / 2 - gravity_torque / gains.stiffness, 1e-6);
  EXPECT_NEAR(held.effort, gravity_torque, 1e-3 * gravity_torque);

  JointCommand turn;
  turn.mode = JointCommandMode::kVelocity;
  turn.velocity = 0.5;
  ASSERT_TRUE(world.SetJointCommand(id, 0, turn).ok());
  for (int step = 0; step < 120; ++step) world.Step();
  EXPECT_NEAR(world.GetJointStates(id)[0].velocity, 0.5, 5e-3);
}

// A 0.2 m box with a 5 cm flap on a continuous hinge on its top, its base
// at `base_z`.
ArticulationDef BoxWithFlap(double base_z) {
  ArticulationDef def;
  def.world_from_base = Translation(0, 0, base_z);
  LinkDef body;
  body.mass_properties = BoxMassProperties(1000.0, Vec3(0.2, 0.2, 0.2));
  ShapeDef box;
  box.geometry = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3(0.2, 0.2, 0.2)));
  box.material = MakeMaterial(0.8, 0.0);
  body.shapes.push_back(box);
  LinkDef flap;
  flap.mass_properties = BoxMassProperties(1000.0, Vec3(0.05, 0.05, 0.05));
  flap.mass_properties.center_of_mass = Vec3(0, 0, 0.05);
  JointDef hinge;
  hinge.name = "flap";
  hinge.type = JointType::kContinuous;
  hinge.parent_from_joint.translation = Vec3(0, 0, 0.1);
  hinge.axis = Vec3::UnitY();
  def.links = {body, flap};
  def.joints = {hinge};
  return def;
}

// A floating two-link articulation (a box with a flap) dropped on the
// ground comes to rest on it at the box's half height, and a refused
// definition leaves the world unchanged.
TEST(ArticulationTest, FloatingArticulationRestsOnTheGround) {
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
TEST(ArticulationTest, ArticulationSpawnedIntoTheGroundRisesWithoutLaunchSpeed) {
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
TEST(ArticulationTest, BouncingArticulationRisesToRestitutionSquaredAndRests) {
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
  // A link has no time-of-impact search: it leaves the ground at e v- up to
  // one step late, which costs at most e v- dt of the rise, v- = sqrt(2 g h);
  // the apex is sampled at steps, within g dt^2 of the true one.
  const double late = kRestitution * std::sqrt(2.0 * kG * kDrop) * kDt;
  EXPECT_NEAR(apex, kRestitution * kRestitution * kDrop, late + kG * kDt * kDt);
  EXPECT_LT(apex, kRestitution * kRestitution * kDrop + kG * kDt * kDt);
  for (int step = 0; step < 3 * 240; ++step) world.Step();
  EXPECT_NEAR(world.GetPose(base).translation.z(), 0.1, 1e-3);
  for (const BodyId link : world.ArticulationLinks(id)) {
    EXPECT_LT(world.GetLinearVelocity(link).norm(), 1e-6);
    EXPECT_LT(world.GetAngularVelocity(link).norm(), 1e-6);
  }
}

// A rigid ball, e = 0.8, dropped h = 0.5 m onto the box of a fixed-base
// box-with-flap bounces to e^2 h, then e^4 h: the restitution pass gives
// it e v- and leaves its drift over the step to where it touches, so it
// rises at most one step late (e v- dt lower) and never higher. Without
// the pass the row that stopped it took its speed (0.012 m of 0.05 for the
// box above); with the bounced speed drifting over the whole step it rose
// 13 mm too high.
TEST(ArticulationTest, RigidBallBouncesOnALinkToRestitutionSquared) {
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

// A damped pendulum at small amplitude: theta'' + (b / I) theta' +
// (m g l / I) theta = 0, whose peaks decay as exp(-b t / (2 I)). The rate
// is measured from the first and the tenth peak, each placed by a parabola
// through the three samples around it.
TEST(ArticulationTest, DampedPendulumDecaysAtTheClosedFormRate) {
  World world = MakeWorld();
  ArticulationDef def;
  def.fixed_base = true;
  def.links = {Anchor(), Rod(1.0, 1.0)};
  JointDef hinge = Hinge(1, 0.0, 0.02);
  hinge.damping = 0.1;  // N m s/rad
  def.joints = {hinge};
  const ArticulationId id = world.CreateArticulation(def).value();
  const double inertia = 1e-4 + 1.0;
  std::vector<std::pair<double, double>> peaks;  // (time, value)
  double a = 0.02;
  double b = 0.02;
  for (int step = 1; peaks.size() < 10 && step < 100000; ++step) {
    world.Step();
    const double c = world.GetJointStates(id)[0].position;
    if (step >= 2 && b > a && b >= c) {
      // Vertex of the parabola through (-1, a), (0, b), (1, c).
      const double offset = 0.5 * (a - c) / (a - 2.0 * b + c);
      const double value = b - 0.25 * (a - c) * offset;
      peaks.emplace_back((step - 1 + offset) * kDt, value);
    }
    a = b;
    b = c;
  }
  ASSERT_EQ(peaks.size(), 10u);
  const double rate = std::log(peaks.front().second / peaks.back().second) /
                      (peaks.back().first - peaks.front().first);
  EXPECT_NEAR(rate / (hinge.damping / (2.0 * inertia)), 1.0, 1e-2);
}

// A light link (0.01 kg at 0.1 m: 1e-4 kg m^2 about its hinge) with
// damping 0.1 N m s on a floating base, without gravity: its joint speed
// decays at about B / I = 1000 1/s, so dt B / I = 4.2 at 1/240 s, beyond
// the stability bound 2.78 of explicit RK4. The decay must be monotone and
// the speed gone within a tenth of a second; taken by RK4 it grew
// sixfold per step.
TEST(ArticulationTest, StiffJointDampingOnAFloatingBaseDecaysMonotonically) {
  WorldSettings settings;
  settings.time_step = kDt;
  settings.gravity = Vec3::Zero();
  World world(settings);
  ArticulationDef def;
  def.links = {Anchor(), Rod(0.01, 0.1)};
  JointDef hinge = Hinge(1, 0.0, 0.0);
  hinge.damping = 0.1;  // N m s/rad
  def.joints = {hinge};
  const ArticulationId id = world.CreateArticulation(def).value();
  ASSERT_TRUE(world.SetJointStates(id, {0.0}, {1.0}).ok());
  double previous = 1.0;
  for (int step = 0; step < 24; ++step) {
    world.Step();
    const double speed = std::abs(world.GetJointStates(id)[0].velocity);
    ASSERT_TRUE(std::isfinite(speed));
    EXPECT_LE(speed, previous) << "step " << step;
    previous = speed;
  }
  EXPECT_LT(previous, 1e-6);
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

JointDef Slider(const std::string& name, int parent, int child, const Vec3& origin,
                const Vec3& axis) {
  JointDef joint;
  joint.name = name;
  joint.type = JointType::kPrismatic;
  joint.parent_link = parent;
  joint.child_link = child;
  joint.parent_from_joint.translation = origin;
  joint.axis = axis;
  joint.lower = -0.5;
  joint.upper = 0.5;
  joint.effort_limit = 1000.0;
  return joint;
}

// A parallel gripper on a lift: two fingers squeeze a 0.2 kg box with 20 N
// each (mu = 1), the lift raises it 0.2 m in 1 s and holds it 5 s. The box
// rises with the hand and slips less than 5 mm relative to it.
TEST(ArticulationTest, GripperLiftsABoxWithoutLettingItSlip) {
  World world = MakeWorld();
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

// A mimic joint follows m q_leader + offset exactly, also when it comes
// before its leader: here two horizontal slides, the first mimicking the
// second (m = -1, offset 0.01 m), the second driven at 0.1 m/s.
TEST(ArticulationTest, MimicJointFollowsItsLeaderWhicheverComesFirst) {
  World world = MakeWorld();
  ArticulationDef def;
  def.fixed_base = true;
  def.links = {Anchor(), Anchor(), Anchor()};
  JointDef mimic = Slider("mimic", 0, 1, Vec3::Zero(), Vec3::UnitX());
  mimic.mimic_joint = 1;
  mimic.mimic_multiplier = -1.0;
  mimic.mimic_offset = 0.01;
  def.joints = {mimic, Slider("leader", 0, 2, Vec3(0, 1, 0), Vec3::UnitX())};
  const ArticulationId id = world.CreateArticulation(def).value();
  JointCommand drive;
  drive.mode = JointCommandMode::kVelocity;
  drive.velocity = 0.1;
  ASSERT_TRUE(world.SetJointCommand(id, 1, drive).ok());
  EXPECT_FALSE(world.SetJointCommand(id, 0, drive).ok());  // a mimic takes no command
  for (int step = 0; step < 240; ++step) world.Step();
  const std::vector<JointState> states = world.GetJointStates(id);
  EXPECT_NEAR(states[1].position, 0.1, 1e-3);
  EXPECT_NEAR(states[0].position, -states[1].position + 0.01, 1e-12);
  EXPECT_NEAR(states[0].velocity, -states[1].velocity, 1e-12);
  const Vec3 link1 = world.GetPose(world.ArticulationLinks(id)[1]).translation;
  EXPECT_NEAR(link1.x(), states[0].position, 1e-12);

  // An effort on the leader is exerted by its mimic too: each 1 kg slide
  // pushed by 5 N moves 1/2 (5 / 1) t^2 in t = 0.4 s.
  World pushed = MakeWorld();
  const ArticulationId pair = pushed.CreateArticulation(def).value();
  JointCommand push;
  push.mode = JointCommandMode::kEffort;
  push.effort = 5.0;
  ASSERT_TRUE(pushed.SetJointCommand(pair, 1, push).ok());
  for (int step = 0; step < 96; ++step) pushed.Step();
  EXPECT_NEAR(pushed.GetJointStates(pair)[1].position, 0.5 * 5.0 * 0.4 * 0.4, 1e-9);
  EXPECT_NEAR(pushed.GetJointStates(pair)[0].effort, -5.0, 1e-9);
}

}  // namespace
}  // namespace rigid_body_sim::physics::testing
