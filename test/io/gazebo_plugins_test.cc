// The Gazebo sensors and ROS plugins of a URDF, read through the loader:
// every field the XML states, the plugins' defaults, the refusals, and
// what lands in `ignored`.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "rigid_body_sim/io/gazebo_plugins.h"
#include "rigid_body_sim/io/urdf_loader.h"

namespace rigid_body_sim::io {
namespace {

using physics::Result;
using physics::Vec3;

std::string Inertial(const std::string& mass, const std::string& inertia) {
  return "<inertial><mass value='" + mass + "'/><inertia " + inertia + "/></inertial>";
}

std::string BoxLink(const std::string& name, const std::string& size) {
  return "<link name='" + name + "'>" + Inertial("1", "ixx='0.01' iyy='0.01' izz='0.01'") +
         "<collision><geometry><box size='" + size + "'/></geometry></collision></link>";
}

std::string Joint(const std::string& name, const std::string& type, const std::string& parent,
                  const std::string& child, const std::string& xyz) {
  return "<joint name='" + name + "' type='" + type + "'><parent link='" + parent +
         "'/><child link='" + child + "'/><origin xyz='" + xyz + "'/><axis xyz='0 1 0'/></joint>";
}

// A small differential-drive robot written as the mobile-robot descriptions
// Gazebo users bring are (a footprint root, wheels on continuous joints, a
// caster, an IMU link and a laser link merged by fixed joints), with the
// elements those descriptions carry besides the ones read: materials,
// contact gains, a plugin-less <sensor type="imu">, a <serviceName>, a
// <rosDebugLevel>, an <imu><noise> block inside the IMU model plugin and
// an <update_rate> inside the laser plugin.
const char kRoverLinks[] = R"(
  <link name="base_footprint"/>
  <joint name="base_joint" type="fixed">
    <parent link="base_footprint"/><child link="base_link"/><origin xyz="0 0 0.02"/>
  </joint>
  <link name="base_link">
    <collision><origin xyz="-0.05 0 0.1"/><geometry><box size="0.3 0.25 0.15"/></geometry></collision>
    <inertial><mass value="3.5"/><inertia ixx="0.03" iyy="0.04" izz="0.05"/></inertial>
  </link>
  <joint name="wheel_left_joint" type="continuous">
    <parent link="base_link"/><child link="wheel_left_link"/>
    <origin xyz="0 0.12 0.03" rpy="-1.5707963 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <link name="wheel_left_link">
    <collision><geometry><cylinder length="0.025" radius="0.05"/></geometry></collision>
    <inertial><mass value="0.1"/><inertia ixx="7e-5" iyy="7e-5" izz="1.25e-4"/></inertial>
  </link>
  <joint name="wheel_right_joint" type="continuous">
    <parent link="base_link"/><child link="wheel_right_link"/>
    <origin xyz="0 -0.12 0.03" rpy="-1.5707963 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <link name="wheel_right_link">
    <collision><geometry><cylinder length="0.025" radius="0.05"/></geometry></collision>
    <inertial><mass value="0.1"/><inertia ixx="7e-5" iyy="7e-5" izz="1.25e-4"/></inertial>
  </link>
  <joint name="caster_back_joint" type="fixed">
    <parent link="base_link"/><child link="caster_back_link"/><origin xyz="-0.16 0 -0.01"/>
  </joint>
  <link name="caster_back_link">
    <collision><geometry><sphere radius="0.01"/></geometry></collision>
    <inertial><mass value="0.01"/><inertia ixx="1e-6" iyy="1e-6" izz="1e-6"/></inertial>
  </link>
  <joint name="imu_joint" type="fixed">
    <parent link="base_link"/><child link="imu_link"/><origin xyz="-0.05 0 0.09"/>
  </joint>
  <link name="imu_link"/>
  <joint name="scan_joint" type="fixed">
    <parent link="base_link"/><child link="base_scan"/><origin xyz="0 0 0.2"/>
  </joint>
  <link name="base_scan">
    <collision><geometry><cylinder length="0.04" radius="0.04"/></geometry></collision>
    <inertial><mass value="0.2"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4"/></inertial>
  </link>
)";

const char kRoverGazebo[] = R"(
  <gazebo reference="base_link"><material>Gazebo/Orange</material></gazebo>
  <gazebo reference="wheel_left_link"><mu1>0.9</mu1><mu2>0.9</mu2><kp>1e6</kp></gazebo>
  <gazebo reference="imu_link">
    <sensor type="imu" name="bare_imu"><always_on>true</always_on></sensor>
  </gazebo>
  <gazebo>
    <plugin name="rover_drive" filename="libgazebo_ros_diff_drive.so">
      <commandTopic>cmd_vel</commandTopic><odometryTopic>odom</odometryTopic>
      <odometryFrame>odom</odometryFrame><robotBaseFrame>base_footprint</robotBaseFrame>
      <publishWheelTF>false</publishWheelTF><publishTf>true</publishTf>
      <publishWheelJointState>true</publishWheelJointState>
      <legacyMode>false</legacyMode><updateRate>50</updateRate>
      <leftJoint>wheel_left_joint</leftJoint><rightJoint>wheel_right_joint</rightJoint>
      <wheelSeparation>0.24</wheelSeparation><wheelDiameter>0.1</wheelDiameter>
      <wheelAcceleration>2</wheelAcceleration><wheelTorque>5</wheelTorque>
      <rosDebugLevel>na</rosDebugLevel>
    </plugin>
  </gazebo>
  <gazebo>
    <plugin name="imu_plugin" filename="libgazebo_ros_imu.so">
      <alwaysOn>true</alwaysOn><bodyName>imu_link</bodyName><topicName>imu</topicName>
      <serviceName>imu_service</serviceName><gaussianNoise>0.0</gaussianNoise>
      <updateRate>100</updateRate>
      <imu><noise><type>gaussian</type>
        <rate><mean>0.0</mean><stddev>3e-4</stddev><bias_mean>1e-5</bias_mean>
          <bias_stddev>1e-6</bias_stddev></rate>
        <accel><mean>0.0</mean><stddev>2e-2</stddev><bias_mean>0.05</bias_mean>
          <bias_stddev>0.002</bias_stddev></accel>
      </noise></imu>
    </plugin>
  </gazebo>
  <gazebo reference="base_scan">
    <material>Gazebo/Black</material>
    <sensor type="ray" name="lidar">
      <pose>0 0 0 0 0 0</pose><visualize>false</visualize><update_rate>10</update_rate>
      <ray>
        <scan><horizontal><samples>720</samples><resolution>1</resolution>
          <min_angle>-3.14159</min_angle><max_angle>3.14159</max_angle></horizontal></scan>
        <range><min>0.15</min><max>6.0</max><resolution>0.01</resolution></range>
        <noise><type>gaussian</type><mean>0.0</mean><stddev>0.02</stddev></noise>
      </ray>
      <plugin name="lidar_controller" filename="libgazebo_ros_laser.so">
        <topicName>scan</topicName><frameName>base_scan</frameName>
        <update_rate>1000</update_rate>
      </plugin>
    </sensor>
  </gazebo>
)";

Result<LoadedModel> LoadArticulated(const std::string& xml) {
  UrdfLoadOptions options;
  options.articulate = true;
  return LoadUrdfString(xml, options);
}

// base with two wheels on continuous joints left_joint and right_joint, a
// fixed `lidar` link and a fixed joint `bracket` to it, plus `extra`.
std::string Rover(const std::string& extra) {
  return "<robot name='rover'>" + BoxLink("base", "0.4 0.3 0.1") +
         BoxLink("wheel_l", "0.1 0.1 0.1") + BoxLink("wheel_r", "0.1 0.1 0.1") +
         BoxLink("lidar", "0.05 0.05 0.05") +
         Joint("left_joint", "continuous", "base", "wheel_l", "0 0.2 0") +
         Joint("right_joint", "continuous", "base", "wheel_r", "0 -0.2 0") +
         Joint("bracket", "fixed", "base", "lidar", "0 0 0.1") + extra + "</robot>";
}

// A laser on `lidar` whose <ray> is `ray`.
std::string Laser(const std::string& ray, const std::string& sensor_extra = "") {
  return "<gazebo reference='lidar'><sensor type='ray' name='laser'>" + sensor_extra + "<ray>" +
         ray + "</ray><plugin name='p' filename='libgazebo_ros_laser.so'/></sensor></gazebo>";
}

const char kRange[] = "<range><min>0.1</min><max>10</max></range>";

TEST(GazeboPluginsTest, AMobileRobotDescriptionReadsEveryField) {
  const Result<LoadedModel> model = LoadArticulated(std::string("<robot name='small_rover'>") +
                                                    kRoverLinks + kRoverGazebo + "</robot>");
  ASSERT_TRUE(model.ok()) << model.message();
  const GazeboPlugins& plugins = model->plugins;
  ASSERT_EQ(plugins.lasers.size(), 1u);
  const LaserSensor& laser = plugins.lasers[0];
  EXPECT_EQ(laser.common.name, "lidar");
  EXPECT_EQ(laser.common.filename, "libgazebo_ros_laser.so");
  // base_scan is merged into base_footprint's body by fixed joints and
  // keeps its name; the node finds it in `links`.
  EXPECT_EQ(laser.common.link, "base_scan");
  EXPECT_TRUE(laser.common.link_from_sensor.translation.isZero());
  EXPECT_TRUE(laser.common.link_from_sensor.rotation.isApprox(physics::Quat::Identity()));
  EXPECT_DOUBLE_EQ(laser.common.update_rate, 10.0);  // the plugin's 1000 is not read
  EXPECT_EQ(laser.common.robot_namespace, "");
  EXPECT_EQ(laser.common.topic, "scan");
  EXPECT_EQ(laser.common.frame_id, "base_scan");
  EXPECT_EQ(laser.horizontal_samples, 720);
  EXPECT_DOUBLE_EQ(laser.horizontal_resolution, 1.0);
  EXPECT_DOUBLE_EQ(laser.min_angle, -3.14159);
  EXPECT_DOUBLE_EQ(laser.max_angle, 3.14159);
  EXPECT_EQ(laser.vertical_samples, 1);
  EXPECT_DOUBLE_EQ(laser.range_min, 0.15);
  EXPECT_DOUBLE_EQ(laser.range_max, 6.0);
  EXPECT_DOUBLE_EQ(laser.range_resolution, 0.01);
  EXPECT_DOUBLE_EQ(laser.noise.mean, 0.0);
  EXPECT_DOUBLE_EQ(laser.noise.stddev, 0.02);
  EXPECT_DOUBLE_EQ(laser.noise.bias_stddev, 0.0);
  EXPECT_FALSE(laser.point_cloud);
  ASSERT_EQ(plugins.imus.size(), 1u);
  const ImuSensor& imu = plugins.imus[0];
  EXPECT_EQ(imu.common.name, "imu_plugin");
  EXPECT_EQ(imu.common.filename, "libgazebo_ros_imu.so");
  EXPECT_EQ(imu.common.link, "imu_link");
  EXPECT_EQ(imu.common.topic, "imu");
  EXPECT_EQ(imu.common.frame_id, "imu_link");
  EXPECT_DOUBLE_EQ(imu.common.update_rate, 100.0);
  // gazebo_ros_imu reads only <gaussianNoise> (0); its <imu><noise> is not.
  EXPECT_TRUE(imu.orientation.IsZero());
  EXPECT_TRUE(imu.angular_velocity.IsZero());
  EXPECT_TRUE(imu.linear_acceleration.IsZero());
  ASSERT_EQ(plugins.diff_drives.size(), 1u);
  const DiffDrive& drive = plugins.diff_drives[0];
  EXPECT_EQ(drive.common.name, "rover_drive");
  EXPECT_EQ(drive.common.filename, "libgazebo_ros_diff_drive.so");
  EXPECT_EQ(drive.common.link, "base_footprint");
  EXPECT_EQ(drive.common.topic, "cmd_vel");
  EXPECT_DOUBLE_EQ(drive.common.update_rate, 50.0);
  EXPECT_EQ(drive.left_joint, "wheel_left_joint");
  EXPECT_EQ(drive.right_joint, "wheel_right_joint");
  EXPECT_DOUBLE_EQ(drive.wheel_separation, 0.24);
  EXPECT_DOUBLE_EQ(drive.wheel_diameter, 0.1);
  EXPECT_DOUBLE_EQ(drive.wheel_torque, 5.0);
  EXPECT_DOUBLE_EQ(drive.wheel_acceleration, 2.0);
  EXPECT_EQ(drive.odometry_topic, "odom");
  EXPECT_EQ(drive.odometry_frame, "odom");
  EXPECT_EQ(drive.robot_base_frame, "base_footprint");
  EXPECT_TRUE(drive.publish_odometry);
  EXPECT_TRUE(drive.publish_tf);
  EXPECT_FALSE(drive.publish_wheel_tf);
  EXPECT_TRUE(drive.publish_wheel_joint_state);
  EXPECT_FALSE(drive.odometry_from_encoders);
  EXPECT_FALSE(drive.legacy_mode);
  EXPECT_TRUE(plugins.bumpers.empty());
  EXPECT_TRUE(plugins.force_torque.empty());
  EXPECT_TRUE(plugins.odometry.empty());
  // The <sensor type="imu"> has no plugin: Gazebo publishes nothing for it.
  EXPECT_EQ(plugins.ignored,
            (std::vector<std::string>{"<gazebo reference='imu_link'> sensor 'bare_imu' (imu)"}));
  EXPECT_EQ(model->ignored, plugins.ignored);
}

TEST(GazeboPluginsTest, MinimalSensorsTakeThePluginsDefaults) {
  const Result<LoadedModel> model = LoadArticulated(Rover(
      Laser(kRange) +
      "<gazebo reference='lidar'><sensor type='imu' name='imu'>"
      "<plugin name='ip' filename='libgazebo_ros_imu_sensor.so'/></sensor>"
      "<sensor type='contact' name='bump'><plugin name='bp' filename='libgazebo_ros_bumper.so'/>"
      "</sensor></gazebo><gazebo>"
      "<plugin name='mi' filename='libgazebo_ros_imu.so'><bodyName>base</bodyName></plugin>"
      "</gazebo>"));
  ASSERT_TRUE(model.ok()) << model.message();
  const GazeboPlugins& plugins = model->plugins;
  ASSERT_EQ(plugins.lasers.size(), 1u);
  const LaserSensor& laser = plugins.lasers[0];
  EXPECT_EQ(laser.common.topic, "/world");
  EXPECT_EQ(laser.common.frame_id, "lidar");  // not the plugin's "/world"
  EXPECT_DOUBLE_EQ(laser.common.update_rate, 0.0);
  EXPECT_EQ(laser.horizontal_samples, 640);
  EXPECT_DOUBLE_EQ(laser.horizontal_resolution, 1.0);
  EXPECT_DOUBLE_EQ(laser.min_angle, 0.0);
  EXPECT_DOUBLE_EQ(laser.max_angle, 0.0);
  EXPECT_EQ(laser.vertical_samples, 1);
  EXPECT_DOUBLE_EQ(laser.range_resolution, 0.0);
  EXPECT_TRUE(laser.noise.IsZero());

  ASSERT_EQ(plugins.imus.size(), 2u);
  const ImuSensor& model_imu = plugins.imus[1];  // in document order
  EXPECT_EQ(model_imu.common.topic, "/default_imu");
  EXPECT_EQ(model_imu.common.frame_id, "base");
  EXPECT_DOUBLE_EQ(model_imu.common.update_rate, 0.0);
  const ImuSensor& sensor_imu = plugins.imus[0];
  EXPECT_EQ(sensor_imu.common.link, "lidar");
  EXPECT_EQ(sensor_imu.common.topic, "imu_data");
  EXPECT_EQ(sensor_imu.common.frame_id, "lidar");
  EXPECT_DOUBLE_EQ(sensor_imu.common.update_rate, 1.0);  // <updateRateHZ>'s default
  EXPECT_TRUE(sensor_imu.angular_velocity.IsZero());

  ASSERT_EQ(plugins.bumpers.size(), 1u);
  EXPECT_EQ(plugins.bumpers[0].common.name, "bump");
  EXPECT_EQ(plugins.bumpers[0].common.link, "lidar");
  EXPECT_EQ(plugins.bumpers[0].common.topic, "bumper_states");
  EXPECT_EQ(plugins.bumpers[0].common.frame_id, "world");
  EXPECT_TRUE(plugins.ignored.empty());
}

TEST(GazeboPluginsTest, MinimalModelPluginsTakeThePluginsDefaults) {
  const Result<LoadedModel> model = LoadArticulated(
      Rover("<gazebo><plugin name='ft' filename='libgazebo_ros_ft_sensor.so'><jointName>bracket"
            "</jointName><topicName>ft</topicName></plugin><plugin name='gt' "
            "filename='libgazebo_ros_p3d.so'><bodyName>base</bodyName><topicName>truth</topicName>"
            "</plugin><plugin name='dd' filename='libgazebo_ros_diff_drive.so'/></gazebo>"));
  ASSERT_TRUE(model.ok()) << model.message();
  const GazeboPlugins& plugins = model->plugins;
  ASSERT_EQ(plugins.force_torque.size(), 1u);
  EXPECT_EQ(plugins.force_torque[0].joint, "bracket");
  EXPECT_EQ(plugins.force_torque[0].common.link, "lidar");
  EXPECT_EQ(plugins.force_torque[0].common.frame_id, "lidar");
  EXPECT_EQ(plugins.force_torque[0].common.topic, "ft");
  EXPECT_DOUBLE_EQ(plugins.force_torque[0].common.update_rate, 0.0);
  EXPECT_TRUE(plugins.force_torque[0].noise.IsZero());

  ASSERT_EQ(plugins.odometry.size(), 1u);
  EXPECT_EQ(plugins.odometry[0].common.link, "base");
  EXPECT_EQ(plugins.odometry[0].common.frame_id, "world");
  EXPECT_EQ(plugins.odometry[0].reference_link, "");
  EXPECT_DOUBLE_EQ(plugins.odometry[0].common.update_rate, 0.0);

  ASSERT_EQ(plugins.diff_drives.size(), 1u);
  const DiffDrive& drive = plugins.diff_drives[0];
  EXPECT_EQ(drive.common.link, "base");
  EXPECT_EQ(drive.common.topic, "cmd_vel");
  EXPECT_DOUBLE_EQ(drive.common.update_rate, 100.0);
  EXPECT_EQ(drive.left_joint, "left_joint");
  EXPECT_EQ(drive.right_joint, "right_joint");
  EXPECT_DOUBLE_EQ(drive.wheel_separation, 0.34);
  EXPECT_DOUBLE_EQ(drive.wheel_diameter, 0.15);
  EXPECT_DOUBLE_EQ(drive.wheel_torque, 5.0);
  EXPECT_DOUBLE_EQ(drive.wheel_acceleration, 0.0);
  EXPECT_EQ(drive.odometry_topic, "odom");
  EXPECT_EQ(drive.odometry_frame, "odom");
  EXPECT_EQ(drive.robot_base_frame, "base_footprint");
  EXPECT_TRUE(drive.publish_odometry);
  EXPECT_TRUE(drive.publish_tf);
  EXPECT_FALSE(drive.publish_wheel_tf);
  EXPECT_FALSE(drive.publish_wheel_joint_state);
  EXPECT_FALSE(drive.odometry_from_encoders);
  EXPECT_FALSE(drive.legacy_mode);
  EXPECT_TRUE(plugins.ignored.empty());
}

TEST(GazeboPluginsTest, LasersReadTheirSdfFields) {
  const Result<LoadedModel> model = LoadArticulated(Rover(
      "<gazebo reference='lidar'><sensor type='gpu_ray' name='velodyne'>"
      "<pose>0.1 0 0.2 0 0 1.5</pose><update_rate>10</update_rate><ray><scan>"
      "<horizontal><samples>1800</samples><resolution>1</resolution><min_angle>-3.14</min_angle>"
      "<max_angle>3.14</max_angle></horizontal><vertical><samples>16</samples>"
      "<resolution>1</resolution><min_angle>-0.26</min_angle><max_angle>0.26</max_angle>"
      "</vertical></scan><range><min>0.3</min><max>100</max><resolution>0.001</resolution>"
      "</range><noise type='gaussian'><mean>0.01</mean><stddev>0.02</stddev></noise></ray>"
      "<plugin name='v' filename='libgazebo_ros_gpu_laser.so'><topicName>points</topicName>"
      "<frameName>velodyne</frameName><robotNamespace>r1</robotNamespace></plugin></sensor>"
      "<sensor type='ray' name='block'><ray><scan><horizontal><samples>4</samples></horizontal>"
      "</scan>" +
      std::string(kRange) +
      "<noise><type>gaussian</type><stddev>0.3</stddev></noise>"
      "</ray><plugin name='b' filename='libgazebo_ros_block_laser.so'>"
      "<gaussianNoise>0.4</gaussianNoise></plugin></sensor></gazebo>"));
  ASSERT_TRUE(model.ok()) << model.message();
  ASSERT_EQ(model->plugins.lasers.size(), 2u);
  const LaserSensor& velodyne = model->plugins.lasers[0];
  EXPECT_EQ(velodyne.common.topic, "points");
  EXPECT_EQ(velodyne.common.frame_id, "velodyne");
  EXPECT_EQ(velodyne.common.robot_namespace, "r1");
  EXPECT_DOUBLE_EQ(velodyne.common.update_rate, 10.0);
  EXPECT_TRUE(velodyne.common.link_from_sensor.translation.isApprox(Vec3(0.1, 0, 0.2)));
  EXPECT_TRUE(velodyne.common.link_from_sensor.rotation.isApprox(
      physics::Quat(Eigen::AngleAxisd(1.5, Vec3::UnitZ()))));
  EXPECT_EQ(velodyne.horizontal_samples, 1800);
  EXPECT_DOUBLE_EQ(velodyne.min_angle, -3.14);
  EXPECT_DOUBLE_EQ(velodyne.max_angle, 3.14);
  EXPECT_EQ(velodyne.vertical_samples, 16);
  EXPECT_DOUBLE_EQ(velodyne.vertical_min_angle, -0.26);
  EXPECT_DOUBLE_EQ(velodyne.vertical_max_angle, 0.26);
  EXPECT_DOUBLE_EQ(velodyne.range_min, 0.3);
  EXPECT_DOUBLE_EQ(velodyne.range_max, 100.0);
  EXPECT_DOUBLE_EQ(velodyne.range_resolution, 0.001);
  EXPECT_DOUBLE_EQ(velodyne.noise.mean, 0.01);
  EXPECT_DOUBLE_EQ(velodyne.noise.stddev, 0.02);
  EXPECT_TRUE(velodyne.point_cloud);
  const LaserSensor& block = model->plugins.lasers[1];
  EXPECT_EQ(block.horizontal_samples, 4);
  EXPECT_TRUE(block.point_cloud);
  EXPECT_NEAR(block.noise.stddev, 0.5, 1e-15);  // hypot(0.3, 0.4)
}

// SDF 1.5's per-axis noise and SDF 1.4's <imu><noise>, with the plugin's.
TEST(GazeboPluginsTest, ImuSensorsReadBothNoiseForms) {
  const Result<LoadedModel> model = LoadArticulated(Rover(
      "<gazebo reference='lidar'><sensor type='imu' name='imu15'><update_rate>50</update_rate>"
      "<imu><angular_velocity><x><noise type='gaussian'><mean>0.1</mean><stddev>0.002</stddev>"
      "<bias_mean>0.3</bias_mean><bias_stddev>0.4</bias_stddev></noise></x><y><noise "
      "type='gaussian'><stddev>0.003</stddev></noise></y><z><noise type='gaussian'><stddev>0.001"
      "</stddev></noise></z></angular_velocity><linear_acceleration><z><noise type='gaussian'>"
      "<stddev>0.017</stddev></noise></z></linear_acceleration></imu><plugin name='i' "
      "filename='libgazebo_ros_imu_sensor.so'><topicName>imu/data</topicName>"
      "<frameName>imu_frame</frameName><updateRateHZ>200</updateRateHZ>"
      "<gaussianNoise>0.004</gaussianNoise><rpyOffset>0 0 1.5</rpyOffset></plugin></sensor>"
      "<sensor type='imu' name='imu14'><imu><noise><type>gaussian</type><rate><stddev>2e-4"
      "</stddev><bias_mean>7.5e-6</bias_mean></rate><accel><mean>0.5</mean><stddev>1.7e-2"
      "</stddev></accel></noise></imu><plugin name='i14' filename='gazebo_ros_imu_sensor'/>"
      "</sensor></gazebo>"));
  ASSERT_TRUE(model.ok()) << model.message();
  ASSERT_EQ(model->plugins.imus.size(), 2u);
  const ImuSensor& imu15 = model->plugins.imus[0];
  EXPECT_EQ(imu15.common.topic, "imu/data");
  EXPECT_EQ(imu15.common.frame_id, "imu_frame");
  EXPECT_DOUBLE_EQ(imu15.common.update_rate, 50.0);          // the slower of 50 and 200
  EXPECT_NEAR(imu15.angular_velocity.stddev, 0.005, 1e-15);  // hypot(y's 0.003, 0.004)
  EXPECT_DOUBLE_EQ(imu15.angular_velocity.mean, 0.0);        // y's block
  EXPECT_NEAR(imu15.linear_acceleration.stddev, std::hypot(0.017, 0.004), 1e-15);
  EXPECT_DOUBLE_EQ(imu15.orientation.stddev, 0.008);
  EXPECT_TRUE(
      imu15.orientation_offset.isApprox(physics::Quat(Eigen::AngleAxisd(1.5, Vec3::UnitZ()))));
  const ImuSensor& imu14 = model->plugins.imus[1];
  EXPECT_DOUBLE_EQ(imu14.common.update_rate, 1.0);
  EXPECT_DOUBLE_EQ(imu14.angular_velocity.stddev, 2e-4);
  EXPECT_DOUBLE_EQ(imu14.angular_velocity.bias_mean, 7.5e-6);
  EXPECT_DOUBLE_EQ(imu14.linear_acceleration.mean, 0.5);
  EXPECT_DOUBLE_EQ(imu14.linear_acceleration.stddev, 1.7e-2);
  EXPECT_TRUE(imu14.orientation.IsZero());
}

TEST(GazeboPluginsTest, ModelPluginsReadTheirFields) {
  const Result<LoadedModel> model = LoadArticulated(Rover(
      "<gazebo reference='bracket'><sensor type='force_torque' name='wrist'>"
      "<update_rate>25</update_rate><plugin name='f' filename='libgazebo_ros_ft_sensor.so'>"
      "<topicName>wrench</topicName><gaussianNoise>0.5</gaussianNoise></plugin></sensor></gazebo>"
      "<gazebo><plugin name='gt' filename='libgazebo_ros_p3d.so'><bodyName>lidar</bodyName>"
      "<topicName>truth</topicName><frameName>base</frameName><updateRate>50</updateRate>"
      "<gaussianNoise>0.01</gaussianNoise><xyzOffset>1 2 3</xyzOffset></plugin><plugin name='dd' "
      "filename='libgazebo_ros_diff_drive.so'><odometrySource>0</odometrySource><publishOdomTF>"
      "FALSE</publishOdomTF><publishWheelTF>1</publishWheelTF><legacyMode>true</legacyMode>"
      "<robotNamespace>/r2</robotNamespace></plugin></gazebo>"));
  ASSERT_TRUE(model.ok()) << model.message();
  const GazeboPlugins& plugins = model->plugins;
  ASSERT_EQ(plugins.force_torque.size(), 1u);
  const ForceTorqueSensor& wrist = plugins.force_torque[0];
  EXPECT_EQ(wrist.common.name, "wrist");
  EXPECT_EQ(wrist.joint, "bracket");
  EXPECT_EQ(wrist.common.link, "lidar");
  EXPECT_EQ(wrist.common.topic, "wrench");
  EXPECT_DOUBLE_EQ(wrist.common.update_rate, 25.0);
  EXPECT_DOUBLE_EQ(wrist.noise.stddev, 0.5);
  ASSERT_EQ(plugins.odometry.size(), 1u);
  const GroundTruthOdometry& truth = plugins.odometry[0];
  EXPECT_EQ(truth.common.link, "lidar");
  EXPECT_EQ(truth.common.frame_id, "base");
  EXPECT_EQ(truth.reference_link, "base");
  EXPECT_DOUBLE_EQ(truth.common.update_rate, 50.0);
  EXPECT_DOUBLE_EQ(truth.noise.stddev, 0.01);
  EXPECT_TRUE(truth.offset.translation.isApprox(Vec3(1, 2, 3)));
  ASSERT_EQ(plugins.diff_drives.size(), 1u);
  const DiffDrive& drive = plugins.diff_drives[0];
  EXPECT_TRUE(drive.odometry_from_encoders);
  EXPECT_TRUE(drive.publish_odometry);
  EXPECT_FALSE(drive.publish_tf);
  EXPECT_TRUE(drive.publish_wheel_tf);
  EXPECT_TRUE(drive.legacy_mode);
  EXPECT_EQ(drive.common.robot_namespace, "/r2");
  EXPECT_TRUE(plugins.ignored.empty());
}

// Each bad value refuses the whole load, naming the element, the field,
// the value and what is allowed.
TEST(GazeboPluginsTest, BadValuesAreRefusedNamingTheField) {
  const std::string dd = "<gazebo><plugin name='dd' filename='libgazebo_ros_diff_drive.so'>";
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {Laser("<range><min>0.1</min><max>-1</max></range>"),
       {"<gazebo reference='lidar'> sensor 'laser' <ray><range><max> -1 is outside the allowed "
        "range (range_min, 1e6] m"}},
      {Laser("<scan><horizontal><samples>0</samples></horizontal></scan>" + std::string(kRange)),
       {"<ray><scan><horizontal><samples> 0 is outside the allowed range [1, 100000]"}},
      {Laser("<scan><horizontal><samples>10.5</samples></horizontal></scan>" + std::string(kRange)),
       {"<samples> 10.5 is not a whole number"}},
      {Laser("<scan><horizontal><samples>1000</samples></horizontal><vertical><samples>1000"
             "</samples></vertical></scan>" +
             std::string(kRange)),
       {"<ray><scan> horizontal samples 1000 times vertical samples 1000", "[1, 100000]"}},
      {Laser(kRange, "<update_rate>nan</update_rate>"),
       {"sensor 'laser' <update_rate> 'nan' is not a finite number"}},
      {Laser(kRange, "<update_rate>2e4</update_rate>"),
       {"<update_rate> 20000 is outside the allowed range [0, 10000] Hz"}},
      {Laser(std::string(kRange) + "<noise><type>gaussian</type><stddev>-0.1</stddev></noise>"),
       {"<ray><noise><stddev> -0.1 is outside the allowed range [0, 1e6]"}},
      {Laser(std::string(kRange) + "<noise type='uniform'/>"), {"<ray><noise> type 'uniform'"}},
      {Laser("<scan><horizontal><min_angle>1</min_angle><max_angle>0.5</max_angle></horizontal>"
             "</scan>" +
             std::string(kRange)),
       {"<max_angle> 0.5 is outside the allowed range [min_angle, 7] rad"}},
      {Laser(kRange, "<pose>0 0 abc 0 0 0</pose>"), {"<pose> '0 0 abc 0 0 0' is not a number"}},
      {"<gazebo reference='nowhere'><sensor type='ray' name='laser'><plugin name='p' "
       "filename='libgazebo_ros_laser.so'/></sensor></gazebo>",
       {"<gazebo reference='nowhere'> sensor 'laser'", "'nowhere' is not a link of the model"}},
      {"<gazebo><plugin name='gt' filename='libgazebo_ros_p3d.so'><bodyName>ghost</bodyName>"
       "<topicName>t</topicName></plugin></gazebo>",
       {"<gazebo> plugin 'gt' (libgazebo_ros_p3d.so) <bodyName> 'ghost' is not a link"}},
      {"<gazebo><plugin name='gt' filename='libgazebo_ros_p3d.so'><bodyName>base</bodyName>"
       "<topicName>t</topicName><frameName>elsewhere</frameName></plugin></gazebo>",
       {"<frameName> 'elsewhere' is neither world, map nor a link of the model"}},
      {"<gazebo><plugin name='mi' filename='libgazebo_ros_imu.so'/></gazebo>",
       {"<gazebo> plugin 'mi' (libgazebo_ros_imu.so) <bodyName> is required"}},
      {"<gazebo><plugin name='ft' filename='libgazebo_ros_ft_sensor.so'><jointName>nope"
       "</jointName><topicName>t</topicName></plugin></gazebo>",
       {"plugin 'ft'", "joint 'nope' is not a joint of the model"}},
      {dd + "<leftJoint>bracket</leftJoint></plugin></gazebo>",
       {"<leftJoint> 'bracket' is fixed; a wheel joint must be revolute or continuous"}},
      {dd + "<rightJoint>missing</rightJoint></plugin></gazebo>",
       {"<rightJoint> 'missing' is not a joint of the model"}},
      {dd + "<wheelDiameter>0</wheelDiameter></plugin></gazebo>",
       {"<wheelDiameter> 0 is outside the allowed range (0, 10000] m"}},
      {dd + "<wheelSeparation>inf</wheelSeparation></plugin></gazebo>",
       {"<wheelSeparation> 'inf' is not a finite number"}},
      {dd + "<updateRate>-1</updateRate></plugin></gazebo>",
       {"<updateRate> -1 is outside the allowed range [0, 10000] Hz"}},
      {dd + "<publishTf>yes</publishTf></plugin></gazebo>", {"<publishTf> 'yes' is not a boolean"}},
      {dd + "<odometrySource>gps</odometrySource></plugin></gazebo>",
       {"<odometrySource> 'gps' is not one of encoder, world, 0 or 1"}},
  };
  for (const auto& [extra, fragments] : cases) {
    const Result<LoadedModel> model = LoadArticulated(Rover(extra));
    ASSERT_FALSE(model.ok()) << extra;
    for (const std::string& fragment : fragments) {
      EXPECT_NE(model.message().find(fragment), std::string::npos)
          << model.message() << "\n  expected: " << fragment;
    }
  }
}

// The joint to 'world' of a static model has no reaction to read.
TEST(GazeboPluginsTest, ForceTorqueOnTheJointToWorldIsRefused) {
  const std::string xml =
      "<robot name='post'><link name='world'/>" + BoxLink("base", "0.1 0.1 0.1") +
      Joint("anchor", "fixed", "world", "base", "0 0 0") +
      "<gazebo><plugin name='ft' filename='libgazebo_ros_ft_sensor.so'><jointName>anchor"
      "</jointName><topicName>t</topicName></plugin></gazebo></robot>";
  const Result<LoadedModel> model = LoadUrdfString(xml);
  ASSERT_FALSE(model.ok());
  EXPECT_NE(model.message().find("joint 'anchor' is the joint to 'world'"), std::string::npos)
      << model.message();
}

// Static and non-articulated models carry their plugins too.
TEST(GazeboPluginsTest, StaticAndWeldedModelsCarryPlugins) {
  const std::string sensor = Laser(kRange);
  const Result<LoadedModel> fixed = LoadUrdfString(
      "<robot name='post'><link name='world'/>" + BoxLink("base", "0.1 0.1 0.1") +
      BoxLink("lidar", "0.05 0.05 0.05") + Joint("anchor", "fixed", "world", "base", "0 0 0") +
      Joint("bracket", "fixed", "base", "lidar", "0 0 0.1") + sensor + "</robot>");
  ASSERT_TRUE(fixed.ok()) << fixed.message();
  EXPECT_TRUE(fixed->is_static);
  ASSERT_EQ(fixed->plugins.lasers.size(), 1u);
  EXPECT_EQ(fixed->plugins.lasers[0].common.link, "lidar");
  UrdfLoadOptions welded;
  welded.weld_movable_joints = true;
  const Result<LoadedModel> rover = LoadUrdfString(Rover(sensor), welded);
  ASSERT_TRUE(rover.ok()) << rover.message();
  EXPECT_FALSE(rover->articulated);
  EXPECT_EQ(rover->plugins.lasers.size(), 1u);
}

// Every other plugin and sensor is listed once, worded as before, after
// the transmissions.
TEST(GazeboPluginsTest, UnknownPluginsAndSensorsAreIgnored) {
  const Result<LoadedModel> model = LoadArticulated(Rover(
      "<transmission name='t1'/><gazebo><plugin name='gazebo_ros_control' "
      "filename='libgazebo_ros_control.so'/><plugin name='gazebo_ros_control' "
      "filename='libgazebo_ros_control.so'/><plugin name='misplaced' "
      "filename='libgazebo_ros_laser.so'/></gazebo><gazebo reference='lidar'><sensor "
      "type='camera' name='cam'><plugin name='c' filename='libgazebo_ros_camera.so'/></sensor>"
      "<sensor type='imu' name='bare'/><sensor type='ray' name='wrong'><plugin name='w' "
      "filename='libgazebo_ros_imu_sensor.so'/></sensor></gazebo>"));
  ASSERT_TRUE(model.ok()) << model.message();
  const std::vector<std::string> gazebo = {
      "<gazebo> plugin 'gazebo_ros_control' (libgazebo_ros_control.so)",
      "<gazebo> plugin 'gazebo_ros_control' (libgazebo_ros_control.so)",
      "<gazebo> plugin 'misplaced' (libgazebo_ros_laser.so)",
      "<gazebo reference='lidar'> sensor 'cam' (camera)",
      "<gazebo reference='lidar'> sensor 'bare' (imu)",
      "<gazebo reference='lidar'> sensor 'wrong' (ray)"};
  EXPECT_EQ(model->plugins.ignored, gazebo);
  // The repeated plugin once.
  std::vector<std::string> all = {"<transmission 't1'>", gazebo[0]};
  all.insert(all.end(), gazebo.begin() + 2, gazebo.end());
  EXPECT_EQ(model->ignored, all);
  EXPECT_TRUE(model->plugins.lasers.empty());
  EXPECT_TRUE(model->plugins.imus.empty());
}

TEST(GazeboPluginsTest, NoGazeboElementsGivesEmptyPlugins) {
  const Result<LoadedModel> model = LoadArticulated(Rover(""));
  ASSERT_TRUE(model.ok()) << model.message();
  const GazeboPlugins& plugins = model->plugins;
  EXPECT_TRUE(plugins.lasers.empty());
  EXPECT_TRUE(plugins.imus.empty());
  EXPECT_TRUE(plugins.bumpers.empty());
  EXPECT_TRUE(plugins.force_torque.empty());
  EXPECT_TRUE(plugins.odometry.empty());
  EXPECT_TRUE(plugins.diff_drives.empty());
  EXPECT_TRUE(plugins.ignored.empty());
  EXPECT_TRUE(model->ignored.empty());
}

}  // namespace
}  // namespace rigid_body_sim::io
