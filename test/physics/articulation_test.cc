// Articulations against closed forms and conservation laws: the pendulum's
// elliptic-integral period, the double pendulum's energy, a tilted prismatic
// joint's acceleration, an inelastic joint limit, a 30-link chain with a
// heavy tip that may not stretch, the servo's and the motor's steady states,
// joint damping, and mimic joints. Contact with links is in
// articulation_contact_test.cc.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "articulation_fixtures.h"
#include "scene.h"

namespace rigid_body_sim::physics::testing {
namespace {

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
// swinging for 10 s (bench/ chain_30): no joint separates, and energy
// stays: it never rises above its start at any step (rounding aside), and
// the split RK4 steps lose at most 1e-4 of the tip's fall m g L.
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
  const double fall = 100.0 * kG * count * 0.1;  // J
  const double start = TotalEnergy(world, chain);
  double worst = 0.0;
  double worst_gain = -fall;
  for (int step = 0; step < 10 * 240; ++step) {
    world.Step();
    worst = std::max(worst, AnchorSeparation(world, chain, def));
    worst_gain = std::max(worst_gain, TotalEnergy(world, chain) - start);
  }
  EXPECT_LT(worst, 1e-6);
  const double end = TotalEnergy(world, chain);
  ASSERT_TRUE(std::isfinite(end));
  EXPECT_LT(end, start + 1e-3 * std::abs(start));
  EXPECT_LT(worst_gain, 1e-9 * fall);
  EXPECT_GT(end - start, -1e-4 * fall);
  std::printf("[measured] heavy-tipped chain (chain_30): worst gain %.3g J, end %.3g J of %.0f J\n",
              worst_gain, end - start, fall);
}

// The heavy tip makes the chain stiff: its light links whip at up to about
// 2 sqrt(T / (m l)) rad/s under the tip's pull T, beyond RK4's stability
// at 1/240 s, and unchecked steps reached 1e193 J within 10 s from any
// start. The motion is conservative (no damping, no efforts), so at every
// step E <= E0 to rounding, from starts 0, 1e-6 and 1e-3 rad off horizontal
// (the energy's balance, articulation_free_motion.cc). The split steps
// stay accurate: E loses at most 1e-3 of the tip's fall, m g L, in 5 s.
TEST(ArticulationTest, StiffChainNeverGainsEnergyFromAnyStart) {
  constexpr int kLinks = 10;
  constexpr double kTip = 100.0;                     // kg
  constexpr double kLength = 0.1;                    // m per link
  const double fall = kTip * kG * kLinks * kLength;  // J
  for (const double offset : {0.0, 1e-6, 1e-3}) {
    SCOPED_TRACE(offset);
    World world = MakeWorld();
    ArticulationDef def;
    def.fixed_base = true;
    def.links.push_back(Anchor());
    for (int i = 1; i <= kLinks; ++i) {
      def.links.push_back(Rod(i == kLinks ? kTip : 0.1, kLength));
      def.joints.push_back(Hinge(i, i == 1 ? 0.0 : kLength, i == 1 ? kPi / 2 + offset : 0.0));
    }
    const ArticulationId chain = world.CreateArticulation(def).value();
    const double start = TotalEnergy(world, chain);
    double worst_gain = -fall;
    for (int step = 0; step < 5 * 240; ++step) {
      world.Step();
      worst_gain = std::max(worst_gain, TotalEnergy(world, chain) - start);
    }
    const double end = TotalEnergy(world, chain);
    ASSERT_TRUE(std::isfinite(end));
    EXPECT_LT(worst_gain, 1e-9 * fall);
    EXPECT_GT(end - start, -1e-3 * fall);
    EXPECT_LT(AnchorSeparation(world, chain, def), 1e-6);
    std::printf(
        "[measured] stiff chain, start %g rad off: worst gain %.3g J, end %.3g J of %.0f J\n",
        offset, worst_gain, end - start, fall);
  }
}

// The largest chain ~max_links_per_model admits: 999 rods of 1 kg and 0.1
// m, coiled 0.3 rad at every joint and falling from its fixed base for 1 s
// (chain_scaling_bench). Its whip needs 8 to 16 RK4 parts per step by the
// energy balance, over the step budget's 4 (FreeMotionIntegrator::
// MostParts): the steps so cut keep the energy to rounding, every state
// finite and no joint apart.
TEST(ArticulationTest, LargestChainKeepsItsEnergyWhereItsStepBudgetCutsTheSplit) {
  constexpr int kJoints = 999;
  World world = MakeWorld();
  ArticulationDef def;
  def.fixed_base = true;
  def.world_from_base = Translation(0, 0, 100);
  def.links.push_back(Anchor());
  for (int i = 1; i <= kJoints; ++i) {
    def.links.push_back(Rod(1.0, 0.1));
    def.joints.push_back(Hinge(i, i == 1 ? 0.0 : 0.1, 0.3));
  }
  const ArticulationId chain = world.CreateArticulation(def).value();
  const double start = TotalEnergy(world, chain);
  double scale = 0.0;  // J, the largest kinetic energy
  double worst_gain = 0.0;
  double worst_loss = 0.0;
  for (int step = 0; step < 240; ++step) {
    world.Step();
    double kinetic = 0.0;
    for (const BodyId link : world.ArticulationLinks(chain)) {
      const Body& body = world.GetBody(link);
      ASSERT_TRUE(body.position.allFinite() && body.linear_velocity.allFinite()) << step;
      kinetic += KineticEnergy(body);
    }
    scale = std::max(scale, kinetic);
    const double change = TotalEnergy(world, chain) - start;
    worst_gain = std::max(worst_gain, change);
    worst_loss = std::max(worst_loss, -change);
  }
  // The sums run over 1000 terms of up to 1e6 J (m g z at z = 100 m).
  const double rounding = 1e-9 * kJoints * kG * 100.0;
  EXPECT_GT(scale, 1e4);  // it fell: the whip is there to be cut
  EXPECT_LT(worst_gain, rounding);
  EXPECT_LT(worst_loss, rounding);
  EXPECT_LT(AnchorSeparation(world, chain, def), 1e-6);
  std::printf("[measured] 999-joint chain, 1 s: kinetic up to %.3g J, energy %+.3g / %+.3g J\n",
              scale, worst_gain, -worst_loss);
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

// A velocity motor with its own cap (max_effort, a drive's wheel torque)
// below the joint's effort limit: a 1 kg slide along x, out of gravity's
// way, driven toward 10 m/s by at most 2 N accelerates at 2 m/s^2, so
// v = 2 t while it is short of the target; with no cap the 1000 N effort
// limit gives 1000 dt m/s in one step. A negative cap is refused.
TEST(ArticulationTest, VelocityMotorAcceleratesAtItsOwnForceCap) {
  ArticulationDef def;
  def.fixed_base = true;
  def.links = {Anchor(), Anchor()};
  def.joints = {Slider("slide", 0, 1, Vec3::Zero(), Vec3::UnitX())};
  def.joints[0].lower = -100.0;
  def.joints[0].upper = 100.0;
  World capped = MakeWorld();
  const ArticulationId id = capped.CreateArticulation(def).value();
  JointCommand drive;
  drive.mode = JointCommandMode::kVelocity;
  drive.velocity = 10.0;
  drive.max_effort = 2.0;
  ASSERT_TRUE(capped.SetJointCommand(id, 0, drive).ok());
  for (int step = 0; step < 240; ++step) capped.Step();
  EXPECT_NEAR(capped.GetJointStates(id)[0].velocity, 2.0 * 1.0, 1e-9);
  EXPECT_NEAR(capped.GetJointStates(id)[0].effort, 2.0, 1e-9);

  World free = MakeWorld();
  const ArticulationId uncapped = free.CreateArticulation(def).value();
  drive.max_effort = 0.0;
  ASSERT_TRUE(free.SetJointCommand(uncapped, 0, drive).ok());
  free.Step();
  EXPECT_NEAR(free.GetJointStates(uncapped)[0].velocity, 1000.0 * kDt, 1e-9);
  drive.max_effort = -1.0;
  EXPECT_FALSE(free.SetJointCommand(uncapped, 0, drive).ok());
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
