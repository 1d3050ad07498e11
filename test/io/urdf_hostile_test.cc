// Hostile URDFs: every one is refused with a message naming the element,
// the value and the allowed range, or loads correctly; none crashes.
#include <gtest/gtest.h>

#include <string>

#include "rigid_body_sim/io/urdf_loader.h"

namespace rigid_body_sim::io {
namespace {

using physics::Result;
using physics::Vec3;

std::string OneLink(const std::string& geometry, const std::string& inertial = "") {
  return "<robot name='r'><link name='base'>" + inertial + "<collision><geometry>" + geometry +
         "</geometry></collision></link></robot>";
}

// `robot` with `elements` added inside <robot>.
std::string WithElements(const std::string& robot, const std::string& elements) {
  const std::string end = "</robot>";
  return robot.substr(0, robot.size() - end.size()) + elements + end;
}

// Expects a refusal whose message holds every one of `words`.
void ExpectRefused(const std::string& xml, std::initializer_list<const char*> words,
                   const UrdfLoadOptions& options = {}) {
  const Result<LoadedModel> model = LoadUrdfString(xml, options);
  ASSERT_FALSE(model.ok());
  for (const char* word : words) {
    EXPECT_NE(model.message().find(word), std::string::npos)
        << "'" << word << "' not in: " << model.message();
  }
}

TEST(UrdfHostileTest, TinyBoxIsRefusedWithItsSizeAndRange) {
  ExpectRefused(OneLink("<box size='1e-7 1e-7 1'/>"),
                {"link 'base'", "<box> size", "1e-07", "[0.0001, 10000]"});
}

TEST(UrdfHostileTest, LongThinCylinderIsRefused) {
  ExpectRefused(OneLink("<cylinder radius='0.01' length='1e5'/>"),
                {"<cylinder> length", "100000", "[0.0001, 10000]"});
  // In range on each size, but 1e4 m long and 0.2 m wide.
  ExpectRefused(OneLink("<cylinder radius='0.1' length='1e4'/>"),
                {"<cylinder>", "aspect ratio", "50000", "1000"});
}

TEST(UrdfHostileTest, NanRadiusIsNamedNotLost) {
  ExpectRefused(OneLink("<cylinder radius='nan' length='1'/>"),
                {"<cylinder> radius='nan'", "not a finite number"});
  ExpectRefused(OneLink("<sphere radius='1e999'/>"), {"<sphere> radius", "not a finite number"});
  ExpectRefused(OneLink("<sphere radius='abc'/>"), {"<sphere> radius", "not a number"});
}

TEST(UrdfHostileTest, HugeOriginsAndInertiaAreRefused) {
  ExpectRefused(
      "<robot name='r'><link name='base'><collision><origin xyz='1e300 0 0'/>"
      "<geometry><sphere radius='1'/></geometry></collision></link></robot>",
      {"<origin> xyz", "1e+300", "[-10000, 10000]"});
  ExpectRefused(OneLink("<sphere radius='1'/>",
                        "<inertial><mass value='1'/><inertia ixx='1e300' iyy='1' izz='1' ixy='0' "
                        "ixz='0' iyz='0'/></inertial>"),
                {"<inertia> ixx", "1e+300"});
  // Finite and small, but no rigid body has these moments: 1 + 1 < 3.
  ExpectRefused(OneLink("<sphere radius='1'/>",
                        "<inertial><mass value='1'/><inertia ixx='1' iyy='1' izz='3' ixy='0' "
                        "ixz='0' iyz='0'/></inertial>"),
                {"triangle inequality"});
}

std::string Chain(int links) {
  std::string xml = "<robot name='chain'>";
  for (int i = 0; i < links; ++i) {
    xml += "<link name='l" + std::to_string(i) +
           "'><collision><geometry><box size='0.1 0.1 0.1'/></geometry></collision></link>";
    if (i > 0) {
      xml += "<joint name='j" + std::to_string(i) + "' type='fixed'><parent link='l" +
             std::to_string(i - 1) + "'/><child link='l" + std::to_string(i) +
             "'/><origin xyz='0 0 0.1'/></joint>";
    }
  }
  return xml + "</robot>";
}

// 10,000 links joined in one chain: refused against the default limit
// without being walked, and loaded without recursion when allowed. Each
// link is a 0.1 m box at 1000 kg/m^3 (1 kg), each 0.1 m above the last, so
// the whole is 10,000 kg with its centre at z = 0.1 * 9999 / 2.
TEST(UrdfHostileTest, TenThousandLinkChainIsRefusedOrLoadedIteratively) {
  const int links = 10000;
  ExpectRefused(Chain(links), {"10000 links", "max_links_per_model 1000"});
  UrdfLoadOptions options;
  options.max_links = links;
  const Result<LoadedModel> model = LoadUrdfString(Chain(links), options);
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_EQ(model->links.size(), static_cast<std::size_t>(links));
  EXPECT_EQ(model->shapes.size(), static_cast<std::size_t>(links));
  EXPECT_EQ(model->links.back().link_name, "l9999");
  EXPECT_NEAR(model->links.back().root_from_link.translation.z(), 999.9, 1e-9);
  EXPECT_NEAR(model->mass_properties.mass, 1.0 * links, 1e-6);
  EXPECT_NEAR(model->mass_properties.center_of_mass.z(), 0.1 * (links - 1) / 2.0, 1e-9);
}

// A chain of `joints` revolute joints between 0.1 m boxes of 1 kg.
std::string HingeChain(int joints) {
  std::string xml = "<robot name='hinges'>";
  for (int i = 0; i <= joints; ++i) {
    xml += "<link name='l" + std::to_string(i) +
           "'><collision><geometry><box size='0.1 0.1 0.1'/></geometry></collision></link>";
    if (i > 0) {
      xml += "<joint name='j" + std::to_string(i) + "' type='revolute'><parent link='l" +
             std::to_string(i - 1) + "'/><child link='l" + std::to_string(i) +
             "'/><origin xyz='0 0 0.1'/><axis xyz='0 1 0'/>"
             "<limit lower='-1' upper='1' effort='10' velocity='1'/></joint>";
    }
  }
  return xml + "</robot>";
}

// The articulation's step grows with its movable joints and holds the
// world lock, so their count has a limit of its own
// (kDefaultMaxJointsPerModel by default), met before anything is built; a
// model whose joints are welded has none to move and is not held to it.
// The default admits every chain the default link limit does, so the links
// are let go beyond it here for the joints' limit to be the one met.
TEST(UrdfHostileTest, MovableJointsBeyondTheLimitAreRefusedByName) {
  UrdfLoadOptions options;
  options.articulate = true;
  options.max_links = 2 * kDefaultMaxJointsPerModel;
  const int limit = kDefaultMaxJointsPerModel;
  const std::string count = std::to_string(limit + 1) + " movable joints";
  const std::string named = "max_joints_per_model " + std::to_string(limit);
  ExpectRefused(HingeChain(limit + 1), {count.c_str(), named.c_str()}, options);
  const Result<LoadedModel> at_limit = LoadUrdfString(HingeChain(limit), options);
  ASSERT_TRUE(at_limit.ok()) << at_limit.message();
  EXPECT_EQ(at_limit->joints.size(), static_cast<std::size_t>(limit));
  // The largest chain the default link limit admits loads by default.
  UrdfLoadOptions defaults;
  defaults.articulate = true;
  EXPECT_TRUE(LoadUrdfString(HingeChain(defaults.max_links - 1), defaults).ok());
  options.max_joints = 65;
  EXPECT_TRUE(LoadUrdfString(HingeChain(65), options).ok());
  options.max_joints = 64;
  options.weld_movable_joints = true;
  EXPECT_TRUE(LoadUrdfString(HingeChain(65), options).ok());
}

// The input on which urdf_loader_fuzzer caught TinyXML reading 12 bytes
// past the end of the text (heap-buffer-overflow under AddressSanitizer,
// during a fuzzing run; it ends in the UTF-8 lead byte 0xe7). It is refused
// by name, and under make test-sanitize read within bounds.
// Joints that do not form a tree are refused before urdfdom builds its
// objects (it links them into shared-pointer cycles that leak when it then
// refuses the model; urdf_loader_fuzzer found the self-joint).
TEST(UrdfHostileTest, JointsThatDoNotFormATreeAreRefused) {
  const std::string links =
      "<link name='a'><collision><geometry><sphere radius='1'/></geometry></collision></link>"
      "<link name='b'><collision><geometry><sphere radius='1'/></geometry></collision></link>"
      "<link name='c'><collision><geometry><sphere radius='1'/></geometry></collision></link>";
  auto joint = [](const std::string& name, const std::string& parent, const std::string& child) {
    return "<joint name='" + name + "' type='fixed'><parent link='" + parent + "'/><child link='" +
           child + "'/></joint>";
  };
  ExpectRefused(
      "<robot name='r'>" + links + joint("j", "a", "b") + joint("self", "c", "c") + "</robot>",
      {"joint 'self'", "link 'c'", "to itself"});
  ExpectRefused(
      "<robot name='r'>" + links + joint("j1", "a", "c") + joint("j2", "b", "c") + "</robot>",
      {"link 'c'", "two joints", "'j1'", "'j2'"});
  ExpectRefused("<robot name='r'>" + links + joint("j1", "a", "b") + joint("j2", "b", "c") +
                    joint("j3", "c", "a") + "</robot>",
                {"cycle"});
}

// A joint's <limit> that every number check passes.
const char kLeaderLimit[] = "<limit lower='-1' upper='1' effort='10' velocity='2'/>";

// A hinge between two 1 kg spheres whose <axis>, <limit> and <dynamics> are
// `elements`.
std::string Hinge(const std::string& elements) {
  const std::string link_body =
      "<inertial><mass value='1'/><inertia ixx='1' iyy='1' izz='1' ixy='0' ixz='0' iyz='0'/>"
      "</inertial><collision><geometry><sphere radius='0.1'/></geometry></collision>";
  return "<robot name='r'><link name='a'>" + link_body + "</link><link name='b'>" + link_body +
         "</link><joint name='hinge' type='revolute'><parent link='a'/><child link='b'/>" +
         elements + "</joint></robot>";
}

// urdfdom keeps a zero axis and negative limits; each is refused by name.
// A huge but finite axis is a direction like any other.
TEST(UrdfHostileTest, JointAxisLimitsAndDynamicsAreChecked) {
  UrdfLoadOptions options;
  options.articulate = true;
  const std::string limit = "<limit lower='-1' upper='1' effort='10' velocity='2'/>";
  ExpectRefused(Hinge("<axis xyz='0 0 0'/>" + limit),
                {"joint 'hinge' <axis>", "xyz='0 0 0'", "zero vector"}, options);
  ExpectRefused(Hinge("<axis xyz='0 1 0'/><limit lower='-1' upper='1' effort='-10' velocity='2'/>"),
                {"joint 'hinge' <limit> effort", "-10", "[0, 1e+300]"}, options);
  ExpectRefused(Hinge("<axis xyz='0 1 0'/><limit lower='-1' upper='1' effort='10' velocity='-2'/>"),
                {"joint 'hinge' <limit> velocity", "-2", "[0, 1e+300]"}, options);
  ExpectRefused(Hinge("<axis xyz='0 1 0'/>" + limit + "<dynamics damping='-1'/>"),
                {"joint 'hinge' <dynamics> damping", "-1", "[0, 1e+300]"}, options);
  ExpectRefused(Hinge("<axis xyz='0 1 0'/>" + limit + "<dynamics friction='1e400'/>"),
                {"joint 'hinge' <dynamics> friction", "not a finite number"}, options);
  const Result<LoadedModel> huge =
      LoadUrdfString(Hinge("<axis xyz='0 1e300 0'/>" + limit), options);
  ASSERT_TRUE(huge.ok()) << huge.message();
  ASSERT_EQ(huge->joints.size(), 1u);
  EXPECT_EQ(huge->joints[0].axis, Vec3::UnitY());
}

// Out of a double's range: overflow is not finite, underflow (a
// subnormal, or 0) is not the number written; each says which.
TEST(UrdfHostileTest, UnderflowAndOverflowAreNamedApart) {
  UrdfLoadOptions options;
  options.articulate = true;
  const std::string limit = "<limit lower='-1' upper='1' effort='10' velocity='2'/>";
  ExpectRefused(Hinge("<axis xyz='1e-320 0 0'/>" + limit),
                {"joint 'hinge' <axis> xyz='1e-320 0 0'", "1e-320 underflows",
                 "below 2.22507e-308, the smallest normal double"},
                options);
  ExpectRefused(Hinge("<axis xyz='1e999 0 0'/>" + limit),
                {"joint 'hinge' <axis> xyz='1e999 0 0'", "not a finite number", "1e999 overflows"},
                options);
  ExpectRefused(OneLink("<sphere radius='1e-400'/>"),
                {"link 'base' <collision> 0 <sphere> radius='1e-400'", "1e-400 underflows"});
  ExpectRefused(WithElements(OneLink("<box size='1 1 1'/>"),
                             "<gazebo reference='base'><mu1>1e-320</mu1></gazebo>"),
                {"<gazebo reference='base'> <mu1>", "'1e-320'", "underflows"});
}

// A revolute or prismatic joint's range must reach within the node's
// +/-1e4: it starts at 0 brought within it. A bound beyond it outwards is
// how descriptions for Gazebo write "unlimited", and loads.
TEST(UrdfHostileTest, JointLimitsReachWithinTheJointPositionBound) {
  UrdfLoadOptions options;
  options.articulate = true;
  ExpectRefused(Hinge("<axis xyz='0 1 0'/><limit lower='2e4' upper='3e4' effort='1' "
                      "velocity='1'/>"),
                {"joint 'hinge' <limit> lower", "20000", "[-1e+300, 10000]"}, options);
  ExpectRefused(Hinge("<axis xyz='0 1 0'/><limit lower='-3e4' upper='-2e4' effort='1' "
                      "velocity='1'/>"),
                {"joint 'hinge' <limit> upper", "-20000", "[-10000, 1e+300]"}, options);
  const Result<LoadedModel> unlimited = LoadUrdfString(
      Hinge("<axis xyz='0 1 0'/><limit lower='-1e+16' upper='1e+16' effort='1' velocity='1'/>"),
      options);
  ASSERT_TRUE(unlimited.ok()) << unlimited.message();
  EXPECT_EQ(unlimited->joints[0].position, 0.0);
  // A position given for the joint is held to the node's bound too.
  options.joint_positions = {{"hinge", 2e4}};
  ExpectRefused(
      Hinge("<axis xyz='0 1 0'/><limit lower='-1e+16' upper='1e+16' effort='1' velocity='1'/>"),
      {"joint 'hinge' position 20000 rad", "[-10000, 10000]"}, options);
}

// <safety_controller> and <calibration>, which the loader does not use, are
// still finite numbers with the gains >= 0.
TEST(UrdfHostileTest, SafetyControllerAndCalibrationNumbersAreChecked) {
  UrdfLoadOptions options;
  options.articulate = true;
  const std::string joint = "<axis xyz='0 1 0'/>" + std::string(kLeaderLimit);
  ExpectRefused(Hinge(joint + "<safety_controller soft_lower_limit='nan' k_velocity='1'/>"),
                {"joint 'hinge' <safety_controller> soft_lower_limit='nan'", "not a finite number"},
                options);
  ExpectRefused(Hinge(joint + "<safety_controller soft_upper_limit='1e400' k_velocity='1'/>"),
                {"joint 'hinge' <safety_controller> soft_upper_limit='1e400'", "overflows"},
                options);
  ExpectRefused(Hinge(joint + "<safety_controller k_position='-5' k_velocity='1'/>"),
                {"joint 'hinge' <safety_controller> k_position", "-5", "[0, 1e+300]"}, options);
  ExpectRefused(Hinge(joint + "<safety_controller k_velocity='-1'/>"),
                {"joint 'hinge' <safety_controller> k_velocity", "-1", "[0, 1e+300]"}, options);
  ExpectRefused(Hinge(joint + "<calibration rising='1e999'/>"),
                {"joint 'hinge' <calibration> rising='1e999'", "not a finite number"}, options);
  ExpectRefused(Hinge(joint + "<calibration falling='1e-310'/>"),
                {"joint 'hinge' <calibration> falling='1e-310'", "underflows"}, options);
  const Result<LoadedModel> fine = LoadUrdfString(
      Hinge(joint + "<safety_controller soft_lower_limit='-0.9' soft_upper_limit='0.9' "
                    "k_position='100' k_velocity='10'/><calibration rising='0.1'/>"),
      options);
  EXPECT_TRUE(fine.ok()) << fine.message();
}

// <mu1> above the node's friction bound 1e3 ("never slides", as Robotiq's
// 1e5 and many wheels' 1e15 mean it) is read as 1e3.
TEST(UrdfHostileTest, HugeGazeboFrictionIsReadAsTheBound) {
  const Result<LoadedModel> model =
      LoadUrdfString(WithElements(OneLink("<box size='1 1 1'/>"),
                                  "<gazebo reference='base'><mu1>1000000000000000.0</mu1>"
                                  "</gazebo>"));
  ASSERT_TRUE(model.ok()) << model.message();
  ASSERT_EQ(model->shapes.size(), 1u);
  EXPECT_EQ(model->shapes[0].shape.material.friction, kMaxFrictionCoefficient);
  EXPECT_TRUE(model->shapes[0].friction_from_urdf);
}

// A palm with two fingers on hinges about y: 'finger_1' limited by
// `leader_limit` (of type `leader_type`), and 'finger_2' mimicking it with
// the attributes `mimic`. `extra` adds elements inside <robot>.
std::string Gripper(const std::string& leader_limit, const std::string& mimic,
                    const std::string& leader_type = "revolute", const std::string& extra = "") {
  const std::string link_body =
      "<inertial><mass value='1'/><inertia ixx='1' iyy='1' izz='1' ixy='0' ixz='0' iyz='0'/>"
      "</inertial><collision><geometry><sphere radius='0.1'/></geometry></collision>";
  std::string xml = "<robot name='gripper'>";
  for (const char* link : {"palm", "finger_1_link", "finger_2_link"}) {
    xml += std::string("<link name='") + link + "'>" + link_body + "</link>";
  }
  return xml + "<joint name='finger_1' type='" + leader_type +
         "'><parent link='palm'/><child link='finger_1_link'/><origin xyz='0 0.5 0'/>"
         "<axis xyz='0 1 0'/>" +
         leader_limit +
         "</joint><joint name='finger_2' type='revolute'><parent link='palm'/>"
         "<child link='finger_2_link'/><origin xyz='0 -0.5 0'/><axis xyz='0 1 0'/>"
         "<limit lower='-1' upper='1' effort='10' velocity='2'/><mimic joint='finger_1' " +
         mimic + "/></joint>" + extra + "</robot>";
}

UrdfLoadOptions Articulated() {
  UrdfLoadOptions options;
  options.articulate = true;
  return options;
}

// Each of a mimic's numbers alone: refused by name, value and range.
TEST(UrdfHostileTest, MimicMultiplierAndOffsetAreRangeChecked) {
  ExpectRefused(Gripper(kLeaderLimit, "multiplier='1' offset='1e300'"),
                {"joint 'finger_2' <mimic> offset", "1e+300", "[-10000, 10000]"}, Articulated());
  ExpectRefused(Gripper(kLeaderLimit, "multiplier='1e300' offset='0'"),
                {"joint 'finger_2' <mimic> multiplier", "1e+300", "[-1000, 1000]"}, Articulated());
  ExpectRefused(Gripper(kLeaderLimit, "multiplier='NaN'"),
                {"joint 'finger_2' <mimic> multiplier='NaN'", "not a finite number"},
                Articulated());
  ExpectRefused(Gripper(kLeaderLimit, "multiplier='two'"),
                {"joint 'finger_2' <mimic> multiplier='two'", "not a number"}, Articulated());
}

// Multiplier and offset each in range, but together beyond +/-1e4 over the
// leader's limits, or beyond the node's joint speed at its velocity limit.
TEST(UrdfHostileTest, MimicRangeOverItsLeadersLimitsIsChecked) {
  ExpectRefused(Gripper("<limit lower='-10' upper='10' effort='10' velocity='2'/>",
                        "multiplier='200' offset='9000'"),
                {"joint 'finger_2' <mimic> position range [7000, 11000] rad",
                 "multiplier 200 times leader 'finger_1' limits [-10, 10]", "offset 9000",
                 "outside the allowed range [-10000, 10000]"},
                Articulated());
  ExpectRefused(
      Gripper("<limit lower='-1' upper='1' effort='10' velocity='200'/>", "multiplier='-100'"),
      {"joint 'finger_2' <mimic> velocity bound 20000 rad/s",
       "|multiplier| 100 times leader 'finger_1' velocity limit 200",
       "outside the allowed range [0, 10000]"},
      Articulated());
  // A continuous leader has no range: only the multiplier and offset are
  // bounded, and the mimic's initial position once the leader's is given.
  const std::string continuous = "<limit effort='10' velocity='2'/>";
  const Result<LoadedModel> wound = LoadUrdfString(
      Gripper(continuous, "multiplier='1000' offset='0'", "continuous"), Articulated());
  ASSERT_TRUE(wound.ok()) << wound.message();
  UrdfLoadOptions given = Articulated();
  given.joint_positions = {{"finger_1", 20.0}};
  ExpectRefused(Gripper(continuous, "multiplier='1000' offset='0'", "continuous"),
                {"joint 'finger_2' <mimic> initial position 20000 rad",
                 "multiplier 1000 times leader 'finger_1' at 20",
                 "outside the allowed range [-10000, 10000]"},
                given);
}

// The leader's effort limit times 1 + its mimics' squared multipliers is
// the effort its dof may get: 200 mimics at 1000 on 1e300 N m overflow it.
TEST(UrdfHostileTest, MimicEffortScaleMustStayFinite) {
  std::string mimics;
  for (int i = 0; i < 200; ++i) {
    const std::string n = std::to_string(i);
    mimics += "<link name='extra_" + n +
              "'><collision><geometry><sphere radius='0.1'/></geometry></collision></link>"
              "<joint name='extra_" +
              n + "' type='revolute'><parent link='palm'/><child link='extra_" + n +
              "'/><axis xyz='0 1 0'/><limit lower='-1' upper='1' effort='1' velocity='1'/>"
              "<mimic joint='finger_1' multiplier='1000'/></joint>";
  }
  // 202 movable joints, within the largest ~max_joints_per_model: the
  // effort scale is what this test is about.
  UrdfLoadOptions options = Articulated();
  options.max_joints = 999;
  ExpectRefused(Gripper("<limit lower='-1' upper='1' effort='1e300' velocity='2'/>",
                        "multiplier='1'", "revolute", mimics),
                {"<mimic> multiplier 1000 raises the effort scale of leader 'finger_1'",
                 "effort limit 1e+300", "not finite"},
                options);
}

// The joint of `model` named `name`.
JointInfo JointNamed(const LoadedModel& model, const std::string& name) {
  for (const JointInfo& joint : model.joints) {
    if (joint.name == name) return joint;
  }
  ADD_FAILURE() << "no joint '" << name << "'";
  return JointInfo{};
}

// A legal mimic loads, and starts at multiplier * its leader's initial
// position + offset, given or not; a multiplier of 0 holds it at its offset.
TEST(UrdfHostileTest, LegalMimicStartsWhereItsLeaderPutsIt) {
  UrdfLoadOptions options = Articulated();
  options.joint_positions = {{"finger_1", 0.3}};
  const Result<LoadedModel> given =
      LoadUrdfString(Gripper(kLeaderLimit, "multiplier='-1' offset='0.1'"), options);
  ASSERT_TRUE(given.ok()) << given.message();
  ASSERT_EQ(given->joints.size(), 2u);
  EXPECT_EQ(JointNamed(*given, "finger_1").position, 0.3);
  const JointInfo mimic = JointNamed(*given, "finger_2");
  EXPECT_NEAR(mimic.position, -1.0 * 0.3 + 0.1, 1e-15);
  EXPECT_EQ(mimic.mimic_joint, "finger_1");
  EXPECT_EQ(mimic.mimic_multiplier, -1.0);
  EXPECT_EQ(mimic.mimic_offset, 0.1);
  // Not given, the leader starts at 0 brought within [0.5, 1]: at 0.5.
  const Result<LoadedModel> clamped =
      LoadUrdfString(Gripper("<limit lower='0.5' upper='1' effort='10' velocity='2'/>",
                             "multiplier='-1' offset='0.1'"),
                     Articulated());
  ASSERT_TRUE(clamped.ok()) << clamped.message();
  EXPECT_EQ(JointNamed(*clamped, "finger_1").position, 0.5);
  EXPECT_NEAR(JointNamed(*clamped, "finger_2").position, -0.5 + 0.1, 1e-15);
  const Result<LoadedModel> held =
      LoadUrdfString(Gripper(kLeaderLimit, "multiplier='0' offset='0.25'"), options);
  ASSERT_TRUE(held.ok()) << held.message();
  EXPECT_EQ(JointNamed(*held, "finger_2").position, 0.25);
}

// urdfdom logs some document text as a printf format (a bad <color rgba>,
// a bad <calibration rising>); with "%s" conversions and no arguments the
// read runs off the stack (found by urdf_loader_fuzzer).
TEST(UrdfHostileTest, PrintfConversionsInTheDocumentAreInert) {
  const std::string conversions = "%s%s%s%s%s%s%s%s%s%s%s%s%s%s%s%s%n";
  const std::string box = "<collision><geometry><box size='1 1 1'/></geometry></collision>";

  // urdfdom logs the bad colour and goes on; the name keeps its '%'.
  const Result<LoadedModel> loaded =
      LoadUrdfString("<robot name='r" + conversions +
                         "'><link name='base'><visual><geometry>"
                         "<box size='1 1 1'/></geometry><material name='m'><color rgba='" +
                         conversions + "'/></material></visual>" + box + "</link></robot>",
                     UrdfLoadOptions{});
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_EQ(loaded->name, "r" + conversions);

  // urdfdom refuses a bad calibration; the refusal still says why.
  const Result<LoadedModel> refused = LoadUrdfString(
      "<robot name='r'><link name='a'>" + box + "</link><link name='b'>" + box +
          "</link><joint name='j' type='revolute'><parent link='a'/><child link='b'/>"
          "<limit lower='-1' upper='1' effort='1' velocity='1'/><calibration rising='" +
          conversions + "'/></joint></robot>",
      UrdfLoadOptions{});
  ASSERT_FALSE(refused.ok());
  for (const char* word :
       {"urdfdom rejected the URDF", "rising value (?s?s?s", "[j]", "each '%' shown as '?'"}) {
    EXPECT_NE(refused.message().find(word), std::string::npos) << refused.message();
  }
}

// urdfdom drops a collision whose geometry it does not know, so the model
// would load without it; the loader names the element instead.
TEST(UrdfHostileTest, UnknownCollisionGeometryIsRefusedByName) {
  ExpectRefused(OneLink("<capsule radius='0.1' length='0.5'/>"),
                {"link 'base' <collision> 0 <capsule>", "not a URDF collision geometry",
                 "<cylinder> with a <sphere> at each end"});
  ExpectRefused(OneLink("<plane normal='0 0 1'/>"),
                {"link 'base' <collision> 0 <plane>", "<box>, <cylinder>, <sphere> or <mesh>"});
  ExpectRefused(OneLink(""), {"link 'base' <collision> 0 <geometry> is empty"});
}

TEST(UrdfHostileTest, DocumentEndingInAUtf8LeadByteIsRefused) {
  const Result<LoadedModel> model =
      LoadUrdfFile(std::string(RBS_TEST_DATA_DIR) + "/utf8_lead_byte_at_end.urdf");
  ASSERT_FALSE(model.ok());
  EXPECT_NE(model.message().find("utf8_lead_byte_at_end.urdf"), std::string::npos)
      << model.message();
  EXPECT_NE(model.message().find("malformed URDF XML"), std::string::npos) << model.message();
}

TEST(UrdfHostileTest, NonRegularAndOversizedFilesAreRefusedBeforeReading) {
  const Result<LoadedModel> zero = LoadUrdfFile("/dev/zero");
  ASSERT_FALSE(zero.ok());
  EXPECT_NE(zero.message().find("not a regular file"), std::string::npos) << zero.message();
  UrdfLoadOptions options;
  options.max_file_bytes = 100;
  const Result<LoadedModel> big = LoadUrdfFile(std::string(RBS_URDF_DIR) + "/box.urdf", options);
  ASSERT_FALSE(big.ok());
  EXPECT_NE(big.message().find("above the limit 100"), std::string::npos) << big.message();
}

TEST(UrdfHostileTest, MeshFromDevZeroIsRefused) {
  const Result<physics::TriangleMesh> mesh = LoadMesh("/dev/zero.stl");
  ASSERT_FALSE(mesh.ok());
  const Result<LoadedModel> model = LoadUrdfString(OneLink("<mesh filename='file:///dev/zero'/>"));
  ASSERT_FALSE(model.ok());
  EXPECT_NE(model.message().find("/dev/zero"), std::string::npos) << model.message();
}

}  // namespace
}  // namespace rigid_body_sim::io
