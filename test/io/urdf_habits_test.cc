// Habits of published robot descriptions that Bullet and Gazebo accept,
// read the same way here: massless links and models, an all-zero inertia,
// tensors that miss the triangle inequality or positive definiteness,
// joint limits that exclude 0,
// a movable joint to 'world', and Gazebo's older <mu1 value="..."/>.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/physics/mass_properties.h"

namespace rigid_body_sim::io {
namespace {

using physics::Result;

std::string Inertial(const std::string& mass, const std::string& moments) {
  return "<inertial><mass value='" + mass + "'/><inertia " + moments +
         " ixy='0' ixz='0' iyz='0'/></inertial>";
}

std::string Link(const std::string& name, const std::string& body) {
  return "<link name='" + name + "'>" + body + "</link>";
}

std::string Box(const std::string& size) {
  return "<collision><geometry><box size='" + size + "'/></geometry></collision>";
}

std::string Hinge(const std::string& parent, const std::string& child, const std::string& limits) {
  return "<joint name='" + parent + "_" + child + "' type='revolute'><parent link='" + parent +
         "'/><child link='" + child + "'/><origin xyz='0 0 0.5'/><axis xyz='0 1 0'/>" + limits +
         "</joint>";
}

const char kZeroMoments[] = "ixx='0' iyy='0' izz='0'";

// Bullet's ground: every link mass 0. Static, and as a static slab its
// 200 x 200 x 0.001 m box may be thinner than a moving body's aspect bound.
TEST(UrdfHabitsTest, ModelWithoutMassIsStaticAndMayBeASlab) {
  const Result<LoadedModel> model = LoadUrdfString(
      "<robot name='plane'>" + Link("ground", Inertial("0", kZeroMoments) + Box("200 200 0.001")) +
      "</robot>");
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_TRUE(model->is_static);
  // The same slab on a moving body is refused by its aspect ratio.
  const Result<LoadedModel> moving = LoadUrdfString(
      "<robot name='slab'>" +
      Link("ground", Inertial("1", "ixx='1' iyy='1' izz='1'") + Box("200 200 0.001")) + "</robot>");
  ASSERT_FALSE(moving.ok());
  EXPECT_NE(moving.message().find("aspect ratio 200000"), std::string::npos) << moving.message();
}

// Mass 2 kg with every <inertia> entry 0 takes its 0.1 x 0.2 x 0.3 m box's
// inertia for 2 kg: I_xx = m (b^2 + c^2) / 12.
TEST(UrdfHabitsTest, AllZeroInertiaComesFromTheGeometryForTheStatedMass) {
  const Result<LoadedModel> model =
      LoadUrdfString("<robot name='box'>" +
                     Link("body", Inertial("2", kZeroMoments) + Box("0.1 0.2 0.3")) + "</robot>");
  ASSERT_TRUE(model.ok()) << model.message();
  const physics::MassProperties& mass = model->mass_properties;
  EXPECT_DOUBLE_EQ(mass.mass, 2.0);
  EXPECT_NEAR(mass.inertia_about_com(0, 0), 2.0 * (0.04 + 0.09) / 12.0, 1e-15);
  EXPECT_NEAR(mass.inertia_about_com(1, 1), 2.0 * (0.01 + 0.09) / 12.0, 1e-15);
  EXPECT_NEAR(mass.inertia_about_com(2, 2), 2.0 * (0.01 + 0.04) / 12.0, 1e-15);
  ASSERT_FALSE(model->warnings.empty());
}

// Moments that miss I1 + I2 >= I3 by 0.8 % (a published two-joint robot's
// link) are raised by one factor until I1 + I2 = I3. By a third they are
// refused, as MuJoCo and Drake refuse them, unless balance_inertia asks for
// the same repair (PR2's sensor_mount_link misses by a factor 5).
TEST(UrdfHabitsTest, TriangleInequalityMissedIsBalancedOrRefused) {
  const double i1 = 0.000913205574, i2 = 0.167168924, i3 = 0.169417871;
  const Result<LoadedModel> model = LoadUrdfString(
      "<robot name='r'>" +
      Link("body", Inertial("1", "ixx='0.000913205574' iyy='0.167168924' izz='0.169417871'") +
                       Box("0.1 0.1 0.1")) +
      "</robot>");
  ASSERT_TRUE(model.ok()) << model.message();
  const physics::Mat3& inertia = model->mass_properties.inertia_about_com;
  const double scale = i3 / (i1 + i2);
  EXPECT_NEAR(inertia(0, 0), i1 * scale, 1e-15);
  EXPECT_NEAR(inertia(1, 1), i2 * scale, 1e-15);
  EXPECT_NEAR(inertia(2, 2), i3, 1e-15);
  EXPECT_NEAR(inertia(0, 0) + inertia(1, 1), inertia(2, 2), 1e-15);

  const std::string far = "<robot name='r'>" +
                          Link("body", Inertial("1", "ixx='1' iyy='1' izz='3'") + Box("1 1 1")) +
                          "</robot>";
  const Result<LoadedModel> refused = LoadUrdfString(far);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("triangle inequality"), std::string::npos);
  EXPECT_NE(refused.message().find("~balance_inertia"), std::string::npos);
  UrdfLoadOptions balance;
  balance.balance_inertia = true;
  const Result<LoadedModel> balanced = LoadUrdfString(far, balance);
  ASSERT_TRUE(balanced.ok()) << balanced.message();
  EXPECT_NEAR(balanced->mass_properties.inertia_about_com(0, 0), 1.5, 1e-12);
  EXPECT_NEAR(balanced->mass_properties.inertia_about_com(1, 1), 1.5, 1e-12);
  EXPECT_NEAR(balanced->mass_properties.inertia_about_com(2, 2), 3.0, 1e-12);
  ASSERT_EQ(balanced->warnings.size(), 1u);
  EXPECT_NE(balanced->warnings[0].find("misses I1 + I2 >= I3"), std::string::npos);
}

// A sensor frame's tensor of 1e-6 in every entry (TIAGo's antennas) has
// principal moments 0, 0 and 3e-6 about n = (1, 1, 1)/sqrt(3): refused by
// default; with balance_inertia the two zero moments are raised to 1e-3 of
// the largest, then to 1.5e-6 each (I1 + I2 = I3), so the tensor is
// 1.5e-6 (1 + n n^T): 2e-6 on the diagonal and 0.5e-6 off it. An all-zero
// tensor without geometry is a ball of water's, 2/5 m r^2 with
// 4/3 pi r^3 1000 kg/m^3 = m; a negative moment is refused by name.
TEST(UrdfHabitsTest, TensorsNotPositiveDefiniteAreRefusedOrRepaired) {
  const std::string singular_urdf =
      "<robot name='r'><link name='body'><inertial><mass value='0.1'/><inertia ixx='1e-6' "
      "ixy='1e-6' ixz='1e-6' iyy='1e-6' iyz='1e-6' izz='1e-6'/></inertial>" +
      Box("0.1 0.1 0.1") + "</link></robot>";
  const Result<LoadedModel> refused = LoadUrdfString(singular_urdf);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("link 'body': invalid <inertial>"), std::string::npos)
      << refused.message();
  UrdfLoadOptions balance;
  balance.balance_inertia = true;
  const Result<LoadedModel> singular = LoadUrdfString(singular_urdf, balance);
  ASSERT_TRUE(singular.ok()) << singular.message();
  const physics::Mat3& inertia = singular->mass_properties.inertia_about_com;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(inertia(r, c), r == c ? 2e-6 : 0.5e-6, 1e-15);
  }
  ASSERT_EQ(singular->warnings.size(), 1u);
  EXPECT_NE(singular->warnings[0].find("is not positive definite"), std::string::npos);
  // A negative principal moment: -3.5e-8 beside 3.5e-8 and 9.1e-8 kg m^2
  // (TIAGo's antenna); balanced, the moments obey I1 + I2 >= I3.
  const std::string negative_moment =
      "<robot name='r'><link name='body'><inertial><mass value='0.1'/><inertia "
      "ixx='2.371e-8' ixy='6.119e-8' ixz='1.179e-8' iyy='2.833e-8' iyz='7.74e-9' "
      "izz='3.849e-8'/></inertial>" +
      Box("0.1 0.1 0.1") + "</link></robot>";
  EXPECT_FALSE(LoadUrdfString(negative_moment).ok());
  const Result<LoadedModel> raised = LoadUrdfString(negative_moment, balance);
  ASSERT_TRUE(raised.ok()) << raised.message();
  const physics::PrincipalAxes axes =
      physics::ComputePrincipalAxes(raised->mass_properties.inertia_about_com);
  EXPECT_GT(axes.principal_moments[0], 0.0);
  EXPECT_NEAR(axes.principal_moments[0] + axes.principal_moments[1], axes.principal_moments[2],
              1e-20);

  const std::string arm = Link("base", Inertial("1", "ixx='1' iyy='1' izz='1'") + Box("1 1 1"));
  const std::string joint =
      "<joint name='weld' type='fixed'><parent link='base'/><child link='sensor'/></joint>";
  const Result<LoadedModel> ball =
      LoadUrdfString("<robot name='r'>" + arm + Link("sensor", Inertial("0.5", kZeroMoments)) +
                     joint + "</robot>");
  ASSERT_TRUE(ball.ok()) << ball.message();
  const double radius = std::cbrt(3.0 * 0.5 / (4.0 * physics::kPi * 1000.0));
  // The box's 1 kg m^2 about each axis plus the ball's, both at the origin.
  EXPECT_NEAR(ball->mass_properties.inertia_about_com(2, 2), 1.0 + 0.4 * 0.5 * radius * radius,
              1e-12);

  const Result<LoadedModel> negative = LoadUrdfString(
      "<robot name='r'>" + Link("body", Inertial("1", "ixx='-1' iyy='1' izz='1'") + Box("1 1 1")) +
      "</robot>");
  ASSERT_FALSE(negative.ok());
  EXPECT_NE(negative.message().find("link 'body': invalid <inertial>: ixx -1 is negative"),
            std::string::npos)
      << negative.message();
}

// An elbow limited to [-1.5, -0.03] rad starts at -0.03 when no position is
// given, and where given when one is.
TEST(UrdfHabitsTest, JointStartsAtZeroBroughtWithinItsLimits) {
  const std::string urdf =
      "<robot name='arm'>" + Link("base", Inertial("1", "ixx='1' iyy='1' izz='1'") + Box("1 1 1")) +
      Link("forearm", Inertial("1", "ixx='1' iyy='1' izz='1'") + Box("1 1 1")) +
      Hinge("base", "forearm", "<limit lower='-1.5' upper='-0.03' effort='10' velocity='1'/>") +
      "</robot>";
  UrdfLoadOptions options;
  options.articulate = true;
  Result<LoadedModel> model = LoadUrdfString(urdf, options);
  ASSERT_TRUE(model.ok()) << model.message();
  ASSERT_EQ(model->joints.size(), 1u);
  EXPECT_EQ(model->joints[0].position, -0.03);
  options.joint_positions = {{"base_forearm", -1.0}};
  model = LoadUrdfString(urdf, options);
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_EQ(model->joints[0].position, -1.0);
}

// Bullet reads a <limit> with lower > upper as no position limit; a fixed
// joint's zero <axis>, never used, is no error.
TEST(UrdfHabitsTest, ReversedLimitsAreNoLimitAndFixedJointsNeedNoAxis) {
  UrdfLoadOptions options;
  options.articulate = true;
  options.joint_positions = {{"base_forearm", 7.0}};
  const Result<LoadedModel> model = LoadUrdfString(
      "<robot name='arm'>" + Link("base", Inertial("1", "ixx='1' iyy='1' izz='1'") + Box("1 1 1")) +
          Link("forearm", Inertial("1", "ixx='1' iyy='1' izz='1'") + Box("1 1 1")) +
          Link("tool", Inertial("1", "ixx='1' iyy='1' izz='1'") + Box("1 1 1")) +
          Hinge("base", "forearm", "<limit lower='1' upper='0' effort='10' velocity='1'/>") +
          "<joint name='weld' type='fixed'><parent link='forearm'/><child link='tool'/>"
          "<axis xyz='0 0 0'/></joint></robot>",
      options);
  ASSERT_TRUE(model.ok()) << model.message();
  ASSERT_EQ(model->joints.size(), 2u);
  EXPECT_EQ(model->joints[0].position, 7.0);
  EXPECT_EQ(model->joints[0].lower, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(model->joints[0].upper, std::numeric_limits<double>::infinity());
}

// An <inertia> giving only ixx, iyy and izz (Bullet's dinnerware) has zero
// products of inertia, and keeps its link's collisions.
TEST(UrdfHabitsTest, LeftOutProductsOfInertiaAreZero) {
  const Result<LoadedModel> model = LoadUrdfString(
      "<robot name='pan'>" +
      Link("body",
           "<inertial><mass value='2'/><inertia ixx='0.005' iyy='0.006' izz='0.0072'/>"
           "</inertial>" +
               Box("0.2 0.2 0.02")) +
      "</robot>");
  ASSERT_TRUE(model.ok()) << model.message();
  ASSERT_EQ(model->shapes.size(), 1u);
  const physics::Mat3& inertia = model->mass_properties.inertia_about_com;
  EXPECT_DOUBLE_EQ(inertia(0, 0), 0.005);
  EXPECT_DOUBLE_EQ(inertia(1, 1), 0.006);
  EXPECT_DOUBLE_EQ(inertia(2, 2), 0.0072);
  EXPECT_DOUBLE_EQ(inertia(0, 1), 0.0);
}

// Bullet's arms state mass 0 for their base: the base is fixed where the
// model is spawned, and the arm's links keep their mass.
TEST(UrdfHabitsTest, ArticulationWithAMasslessBaseIsFixed) {
  UrdfLoadOptions options;
  options.articulate = true;
  const Result<LoadedModel> model = LoadUrdfString(
      "<robot name='arm'>" + Link("base", Inertial("0", kZeroMoments) + Box("0.2 0.2 0.1")) +
          Link("link1", Inertial("3", "ixx='0.1' iyy='0.1' izz='0.1'") + Box("0.1 0.1 0.5")) +
          Hinge("base", "link1", "<limit lower='-2' upper='2' effort='10' velocity='1'/>") +
          "</robot>",
      options);
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_FALSE(model->is_static);
  EXPECT_DOUBLE_EQ(model->mass_properties.mass, 3.0);
  std::vector<std::string> warnings;
  const Result<physics::ArticulationDef> def = MakeArticulationDef(*model, &warnings);
  ASSERT_TRUE(def.ok()) << def.message();
  EXPECT_TRUE(def->fixed_base);
  EXPECT_DOUBLE_EQ(def->links[1].mass_properties.mass, 3.0);
}

// <mu1 value="0.3"/> is read like <mu1>0.3</mu1>.
TEST(UrdfHabitsTest, GazeboFrictionMayBeAnAttribute) {
  const Result<LoadedModel> model = LoadUrdfString(
      "<robot name='r'>" + Link("body", Inertial("1", "ixx='1' iyy='1' izz='1'") + Box("1 1 1")) +
      "<gazebo reference='body'><mu1 value='0.3'/></gazebo></robot>");
  ASSERT_TRUE(model.ok()) << model.message();
  ASSERT_EQ(model->shapes.size(), 1u);
  EXPECT_TRUE(model->shapes[0].friction_from_urdf);
  EXPECT_DOUBLE_EQ(model->shapes[0].shape.material.friction, 0.3);
}

// What a Gazebo description asks for that does not run here (ros_control's
// transmissions, Gazebo's plugins and sensors) is listed, once each and in
// document order, for the spawn reply to say; xacro left unexpanded says
// so instead of "not a number".
TEST(UrdfHabitsTest, TransmissionsPluginsAndSensorsAreListedAsIgnored) {
  const std::string xml =
      "<robot name='r'>" + Link("base", Box("0.1 0.1 0.1")) +
      "<transmission name='tran1'><type>transmission_interface/SimpleTransmission</type>"
      "</transmission><transmission name='tran1'/><gazebo><plugin name='gazebo_ros_control' "
      "filename='libgazebo_ros_control.so'/></gazebo><gazebo reference='base'><sensor "
      "type='camera' name='cam'><plugin name='camera' filename='libgazebo_ros_camera.so'/></sensor>"
      "</gazebo></robot>";
  const Result<LoadedModel> model = LoadUrdfString(xml, {});
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_EQ(model->ignored,
            (std::vector<std::string>{"<transmission 'tran1'>",
                                      "<gazebo> plugin 'gazebo_ros_control' "
                                      "(libgazebo_ros_control.so)",
                                      "<gazebo reference='base'> sensor 'cam' (camera)"}));
  const Result<LoadedModel> unexpanded =
      LoadUrdfString("<robot name='r'>" + Link("base", Box("${s} 1 1")) + "</robot>", {});
  ASSERT_FALSE(unexpanded.ok());
  EXPECT_NE(unexpanded.message().find("unexpanded xacro"), std::string::npos)
      << unexpanded.message();
  const Result<LoadedModel> xacro =
      LoadUrdfString("<robot name='r' xmlns:xacro='http://www.ros.org/wiki/xacro'>" +
                         Link("base", Box("1 1 1")) + "</robot>",
                     {});
  ASSERT_FALSE(xacro.ok());
  EXPECT_NE(xacro.message().find("the description is xacro"), std::string::npos) << xacro.message();
}

}  // namespace
}  // namespace rigid_body_sim::io
