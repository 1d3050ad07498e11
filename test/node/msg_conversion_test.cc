// Conversions between ROS messages and core types; no ROS master needed.
#include "rigid_body_sim/node/msg_conversion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <memory>

namespace rigid_body_sim::node {
namespace {

using physics::Pose;
using physics::Quat;
using physics::Vec3;

geometry_msgs::Pose MsgPose(double x, double y, double z, double qw, double qx, double qy,
                            double qz) {
  geometry_msgs::Pose pose;
  pose.position.x = x;
  pose.position.y = y;
  pose.position.z = z;
  pose.orientation.w = qw;
  pose.orientation.x = qx;
  pose.orientation.y = qy;
  pose.orientation.z = qz;
  return pose;
}

TEST(MsgConversionTest, NonUnitQuaternionIsNormalised) {
  const auto pose = PoseFromMsg(MsgPose(1, 2, 3, 0.0, 0.0, 0.0, 4.0), "pose");
  ASSERT_TRUE(pose.ok()) << pose.message();
  EXPECT_NEAR(pose->rotation.z(), 1.0, 1e-15);
  EXPECT_NEAR(pose->rotation.norm(), 1.0, 1e-15);
  EXPECT_EQ(pose->translation, Vec3(1, 2, 3));
}

TEST(MsgConversionTest, ZeroQuaternionAndNonFiniteValuesAreRefusedByField) {
  const auto zero = PoseFromMsg(MsgPose(0, 0, 0, 0, 0, 0, 0), "pose");
  ASSERT_FALSE(zero.ok());
  EXPECT_EQ(zero.message(),
            "pose.orientation (w, x, y, z) = (0, 0, 0, 0) is a zero quaternion: norm 0 outside "
            "the allowed range [1e-09, 1e+09]");
  const auto nan = PoseFromMsg(MsgPose(0, std::nan(""), 0, 1, 0, 0, 0), "pose");
  ASSERT_FALSE(nan.ok());
  EXPECT_EQ(nan.message(), "pose.position [0, nan, 0] is not finite");
  const auto inf =
      PoseFromMsg(MsgPose(0, 0, 0, std::numeric_limits<double>::infinity(), 0, 0, 0), "pose");
  ASSERT_FALSE(inf.ok());
  EXPECT_EQ(inf.message(), "pose.orientation (w, x, y, z) = (inf, 0, 0, 0) is not finite");
  geometry_msgs::Twist twist;
  twist.angular.y = std::nan("");
  const auto state = FrameStateFromMsg(MsgPose(0, 0, 0, 1, 0, 0, 0), twist);
  ASSERT_FALSE(state.ok());
  EXPECT_EQ(state.message(), "twist.angular [0, nan, 0] is not finite");
}

// 1e300 on every component: norm() overflows to infinity and normalising
// gave a zero quaternion ("norm 0.000000"); the stable norm is 2e300,
// refused by name, and 1e200s are normalised exactly.
TEST(MsgConversionTest, HugeQuaternionIsRefusedWithItsNorm) {
  const auto huge = PoseFromMsg(MsgPose(0, 0, 0, 1e300, 1e300, 1e300, 1e300), "pose");
  ASSERT_FALSE(huge.ok());
  EXPECT_EQ(huge.message(),
            "pose.orientation (w, x, y, z) = (1e+300, 1e+300, 1e+300, 1e+300) has norm 2e+300 "
            "outside the allowed range [1e-09, 1e+09]");
  const auto large = PoseFromMsg(MsgPose(0, 0, 0, 0, 0, 0, 1e8), "pose");
  ASSERT_TRUE(large.ok()) << large.message();
  EXPECT_EQ(large->rotation.z(), 1.0);
}

TEST(MsgConversionTest, SimTimeToRosClampsInsteadOfThrowing) {
  EXPECT_EQ(SimTimeToRos(1.25), ros::Time(1, 250000000));
  EXPECT_EQ(SimTimeToRos(-3.0), ros::Time(0));
  EXPECT_EQ(SimTimeToRos(std::nan("")), ros::Time(0));
  // ros::Time(5e9) would throw std::runtime_error.
  EXPECT_EQ(SimTimeToRos(5e9), ros::TIME_MAX);
  EXPECT_EQ(SimTimeToRos(std::numeric_limits<double>::infinity()), ros::TIME_MAX);
}

TEST(MsgConversionTest, SpawnJointFieldsPairUpWithoutRepeats) {
  rigid_body_sim::Spawn::Request request;
  request.name = "arm";
  request.pose.orientation.w = 1.0;
  request.joint_names = {"elbow", "wrist"};
  request.joint_positions = {0.5, -0.25};
  const auto spec = ModelSpecFromMsg(request);
  ASSERT_TRUE(spec.ok()) << spec.message();
  EXPECT_EQ(spec->joint_positions,
            (std::map<std::string, double>{{"elbow", 0.5}, {"wrist", -0.25}}));
  request.joint_positions = {0.5};
  EXPECT_EQ(ModelSpecFromMsg(request).message(), "joint_positions has 1 values for 2 joint_names");
  request.joint_names = {"elbow", "elbow"};
  request.joint_positions = {0.5, 0.6};
  EXPECT_EQ(ModelSpecFromMsg(request).message(), "joint_names[1] 'elbow' is given twice");
}

TEST(MsgConversionTest, PoseAndTwistRoundTrip) {
  const Pose pose{Vec3(0.5, -1.5, 2.5), Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()))};
  const auto back = PoseFromMsg(PoseToMsg(pose), "pose");
  ASSERT_TRUE(back.ok());
  EXPECT_TRUE(back->translation.isApprox(pose.translation, 1e-15));
  EXPECT_NEAR(std::abs(back->rotation.dot(pose.rotation)), 1.0, 1e-15);
  const geometry_msgs::Twist twist = TwistToMsg(Vec3(1, 2, 3), Vec3(4, 5, 6));
  EXPECT_EQ(twist.linear.y, 2.0);
  EXPECT_EQ(twist.angular.z, 6.0);
  const auto transform = TransformToMsg(pose, "world", "m/l", ros::Time(2.5));
  EXPECT_EQ(transform.header.frame_id, "world");
  EXPECT_EQ(transform.child_frame_id, "m/l");
  EXPECT_EQ(transform.header.stamp.toSec(), 2.5);
  EXPECT_EQ(transform.transform.translation.z, 2.5);
  EXPECT_EQ(transform.transform.rotation.w, pose.rotation.w());
}

TEST(MsgConversionTest, SpawnRequestBecomesSpec) {
  rigid_body_sim::Spawn::Request request;
  request.name = "box1";
  request.urdf_path = "package://rigid_body_sim/urdf/box.urdf";
  request.pose = MsgPose(0, 0, 2, 1, 0, 0, 0);
  request.twist.linear.x = 3.0;
  request.is_static = true;
  request.friction = 0.25;
  request.restitution = -1.0;
  const auto spec = ModelSpecFromMsg(request);
  ASSERT_TRUE(spec.ok());
  EXPECT_EQ(spec->name, "box1");
  EXPECT_EQ(spec->urdf_path, request.urdf_path);
  EXPECT_EQ(spec->root_state.world_from_frame.translation.z(), 2.0);
  EXPECT_EQ(spec->root_state.linear_velocity.x(), 3.0);
  EXPECT_TRUE(spec->is_static);
  EXPECT_EQ(spec->friction, 0.25);
  EXPECT_EQ(spec->restitution, -1.0);
}

TEST(MsgConversionTest, ContactFieldsAndTypeConstants) {
  physics::ContactReport report;
  report.position_world = Vec3(1, 2, 0);
  report.normal_world = Vec3(0, 0, 1);
  report.depth = 0.001;
  report.normal_velocity = -2.0;
  report.type = physics::ContactType::kColliding;
  report.normal_impulse = 3.0;
  report.friction_impulse_world = Vec3(0.1, 0, 0);
  report.normal_force = 720.0;
  const rigid_body_sim::Contact msg = ContactToMsg(report, "ball/base_link", "ground");
  EXPECT_EQ(msg.body_a, "ball/base_link");
  EXPECT_EQ(msg.body_b, "ground");
  EXPECT_EQ(msg.type, rigid_body_sim::Contact::COLLIDING);
  EXPECT_EQ(msg.position.y, 2.0);
  EXPECT_EQ(msg.normal.z, 1.0);
  EXPECT_EQ(msg.depth, 0.001);
  EXPECT_EQ(msg.normal_velocity, -2.0);
  EXPECT_EQ(msg.normal_impulse, 3.0);
  EXPECT_EQ(msg.friction_impulse.x, 0.1);
  EXPECT_EQ(msg.normal_force, 720.0);
  report.type = physics::ContactType::kResting;
  EXPECT_EQ(ContactToMsg(report, "", "").type, rigid_body_sim::Contact::RESTING);
  report.type = physics::ContactType::kSeparating;
  EXPECT_EQ(ContactToMsg(report, "", "").type, rigid_body_sim::Contact::SEPARATING);
}

TEST(MsgConversionTest, ShapeMarkersDrawEveryShapeKind) {
  std::vector<physics::ShapeDef> shapes(3);
  shapes[0].geometry = physics::Sphere{0.25};
  shapes[0].body_from_shape.translation = Vec3(0, 0, 1);
  shapes[1].geometry = std::make_shared<const physics::ConvexPolyhedron>(
      physics::MakeBoxPolyhedron(Vec3(1.0, 2.0, 3.0)));
  shapes[2].geometry = physics::HalfSpace{};
  const auto markers = ShapeMarkers(shapes, "m", "m/base_link", 20.0);
  ASSERT_EQ(markers.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(markers[i].ns, "m");
    EXPECT_EQ(markers[i].id, i);
    EXPECT_EQ(markers[i].header.frame_id, "m/base_link");
    EXPECT_TRUE(markers[i].frame_locked);
  }
  EXPECT_EQ(markers[0].type, visualization_msgs::Marker::SPHERE);
  EXPECT_EQ(markers[0].scale.x, 0.5);
  EXPECT_EQ(markers[0].pose.position.z, 1.0);
  EXPECT_EQ(markers[1].type, visualization_msgs::Marker::TRIANGLE_LIST);
  ASSERT_EQ(markers[1].points.size(), 36u);
  // Signed volume of the triangle fan from the origin: the box's 6 m^3, and
  // positive, so the triangles face outwards.
  double volume = 0.0;
  for (std::size_t i = 0; i < 36; i += 3) {
    const auto& a = markers[1].points[i];
    const auto& b = markers[1].points[i + 1];
    const auto& c = markers[1].points[i + 2];
    volume += Vec3(a.x, a.y, a.z).dot(Vec3(b.x, b.y, b.z).cross(Vec3(c.x, c.y, c.z))) / 6.0;
  }
  EXPECT_NEAR(volume, 6.0, 1e-12);
  EXPECT_EQ(markers[2].type, visualization_msgs::Marker::CUBE);
  EXPECT_EQ(markers[2].scale.x, 20.0);
  EXPECT_LT(markers[2].pose.position.z, 0.0);
  const auto deletes = DeleteMarkers("m", 3);
  ASSERT_EQ(deletes.size(), 3u);
  EXPECT_EQ(deletes[2].id, 2);
  EXPECT_EQ(deletes[2].action, visualization_msgs::Marker::DELETE);
}

TEST(MsgConversionTest, ContactMarkersScaleByForceAndRemoveVanishedContacts) {
  std::vector<physics::ContactReport> contacts(2);
  contacts[0].position_world = Vec3(1, 0, 0);
  contacts[0].normal_world = Vec3(0, 0, 1);
  contacts[0].normal_force = 9.81;
  contacts[0].type = physics::ContactType::kResting;
  contacts[1].type = physics::ContactType::kColliding;
  contacts[1].normal_force = 0.0;
  ContactMarkerStyle style;
  style.frame = "world";
  style.force_scale = 0.02;
  style.min_arrow = 0.05;
  const auto array = ContactMarkers(contacts, 3, style);
  ASSERT_EQ(array.markers.size(), 6u);
  EXPECT_EQ(array.markers[0].type, visualization_msgs::Marker::SPHERE);
  const auto& arrow = array.markers[1];
  EXPECT_EQ(arrow.type, visualization_msgs::Marker::ARROW);
  ASSERT_EQ(arrow.points.size(), 2u);
  EXPECT_NEAR(arrow.points[1].z - arrow.points[0].z, 9.81 * 0.02, 1e-15);
  EXPECT_GT(arrow.color.g, arrow.color.r);  // resting: green
  const auto& short_arrow = array.markers[3];
  EXPECT_NEAR(short_arrow.points[1].z - short_arrow.points[0].z, 0.05, 1e-15);
  EXPECT_GT(short_arrow.color.r, short_arrow.color.g);  // colliding: red
  EXPECT_EQ(array.markers[4].id, 4);
  EXPECT_EQ(array.markers[4].action, visualization_msgs::Marker::DELETE);
  EXPECT_EQ(array.markers[5].id, 5);
  EXPECT_EQ(array.markers[5].action, visualization_msgs::Marker::DELETE);
}

}  // namespace
}  // namespace rigid_body_sim::node
