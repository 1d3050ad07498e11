// The sensors and ROS plugins a URDF declares for Gazebo in its <gazebo>
// elements, read into plain settings with units: lasers, IMUs, bumpers,
// force-torque sensors, ground-truth odometry and differential drives.
// ROS-free: the node turns them into topics (node/sensors.h).
#ifndef RIGID_BODY_SIM_IO_GAZEBO_PLUGINS_H_
#define RIGID_BODY_SIM_IO_GAZEBO_PLUGINS_H_

#include <string>
#include <vector>

#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

// Gaussian noise as SDF's <noise type="gaussian"> writes it: each reading
// gets mean + N(0, stddev^2), plus a bias drawn once per sensor (at spawn)
// from N(bias_mean, bias_stddev^2) with a random sign, as Gazebo's
// GaussianNoiseModel does. All in the reading's unit.
struct GaussianNoise {
  double mean = 0.0;
  double stddev = 0.0;  // >= 0
  double bias_mean = 0.0;
  double bias_stddev = 0.0;  // >= 0
  bool IsZero() const {
    return mean == 0.0 && stddev == 0.0 && bias_mean == 0.0 && bias_stddev == 0.0;
  }
};

// What every sensor and plugin has.
struct PluginCommon {
  std::string name;      // <sensor name>, else <plugin name>
  std::string filename;  // <plugin filename>, e.g. libgazebo_ros_laser.so
  // The link it rides on: <gazebo reference="LINK">, or <bodyName>.
  std::string link;
  // <sensor><pose>, in the link frame; identity for a model plugin (whose
  // <xyzOffset>/<rpyOffset> act on its readings, see ImuSensor and
  // GroundTruthOdometry).
  physics::Pose link_from_sensor;
  // Hz, >= 0; 0 publishes after every step (SDF's "as fast as possible").
  double update_rate = 0.0;
  // The plugin's <robotNamespace>; empty: the model's robot namespace (the
  // spawn service writes its robot_namespace into every plugin without one).
  std::string robot_namespace;
  // As written (<topicName>, <bumperTopicName>, ...); relative to the
  // namespace unless it starts with '/'. Defaults are the plugin's.
  std::string topic;
  // <frameName> (<frame_name>); default: the link's name.
  std::string frame_id;
};

// <sensor type="ray"|"gpu_ray"> with libgazebo_ros_laser.so,
// libgazebo_ros_gpu_laser.so or libgazebo_ros_block_laser.so.
struct LaserSensor {
  PluginCommon common;
  int horizontal_samples = 1;  // [1, kMaxLaserSamples]
  double horizontal_resolution = 1.0;
  double min_angle = 0.0;  // rad, about the sensor's z from its x
  double max_angle = 0.0;  // rad, >= min_angle
  int vertical_samples = 1;
  double vertical_min_angle = 0.0;  // rad, elevation
  double vertical_max_angle = 0.0;
  double range_min = 0.0;         // m, >= 0
  double range_max = 0.0;         // m, > range_min
  double range_resolution = 0.0;  // m, >= 0; 0 leaves ranges unrounded
  // m, on each range: <ray><noise>, and the block laser's <gaussianNoise>
  // (which it adds to each point's x, y and z) with their variances added.
  GaussianNoise noise;
  // A point cloud instead of sensor_msgs/LaserScan: vertical_samples > 1 or
  // the block laser.
  bool point_cloud = false;
};
inline constexpr int kMaxLaserSamples = 100000;  // per axis and in all

// <sensor type="imu"> with libgazebo_ros_imu_sensor.so, or the model plugin
// libgazebo_ros_imu.so with <bodyName>.
struct ImuSensor {
  PluginCommon common;
  GaussianNoise orientation;          // rad, on each axis of a small rotation
  GaussianNoise angular_velocity;     // rad/s, each axis
  GaussianNoise linear_acceleration;  // m/s^2, each axis
  // <rpyOffset>: the reported orientation is this times the true one (both
  // plugins premultiply it; <xyzOffset> moves nothing they publish).
  physics::Quat orientation_offset = physics::Quat::Identity();
};

// <sensor type="contact"> with libgazebo_ros_bumper.so: the link's contacts.
struct BumperSensor {
  PluginCommon common;
};

// libgazebo_ros_ft_sensor.so (model plugin with <jointName>, or in a
// <sensor type="force_torque"> of <gazebo reference="JOINT">): the joint's
// reaction wrench on its child link, in the child link's frame at its
// origin.
struct ForceTorqueSensor {
  PluginCommon common;  // link: the joint's child link
  std::string joint;
  GaussianNoise noise;  // N and N m, each component (<gaussianNoise>)
};

// libgazebo_ros_p3d.so: the true pose and twist of <bodyName>, relative to
// <frameName> (world, map or another link of the model).
struct GroundTruthOdometry {
  PluginCommon common;  // frame_id: <frameName> as written; link: the body
  // The link of the model that <frameName> names; empty for world, map,
  // /world, /map or "": the world frame.
  std::string reference_link;
  GaussianNoise noise;  // m and m/s, rad and rad/s (<gaussianNoise>)
  // <xyzOffset> added to the reported position and <rpyOffset>
  // premultiplying the reported orientation, in the reference frame, as the
  // plugin applies them.
  physics::Pose offset;
};

// libgazebo_ros_diff_drive.so.
struct DiffDrive {
  // topic: <commandTopic>; link: the model's root link; frame_id:
  // odometry_frame.
  PluginCommon common;
  std::string left_joint;  // revolute or continuous joints of the model
  std::string right_joint;
  double wheel_separation = 0.34;   // m, > 0
  double wheel_diameter = 0.15;     // m, > 0
  double wheel_torque = 5.0;        // N m, > 0: the wheels' effort limit
  double wheel_acceleration = 0.0;  // m/s^2 of the wheels' rims, >= 0; 0: at once
  std::string odometry_topic = "odom";
  std::string odometry_frame = "odom";
  std::string robot_base_frame = "base_footprint";
  // <publishTf>: the odometry topic at all (the plugin publishes neither
  // odometry nor its transform without it).
  bool publish_odometry = true;
  // odometry_frame -> robot_base_frame: <publishTf> and <publishOdomTF>.
  bool publish_tf = true;
  bool publish_wheel_tf = false;
  bool publish_wheel_joint_state = false;
  bool odometry_from_encoders = false;  // <odometrySource>encoder; else world
  // <legacyMode>: left and right swapped, as kinetic's plugin did by
  // default; noetic's removed the mode (gazebo_ros_pkgs #707), so false
  // unless a description asks for it.
  bool legacy_mode = false;
};

struct GazeboPlugins {
  std::vector<LaserSensor> lasers;
  std::vector<ImuSensor> imus;
  std::vector<BumperSensor> bumpers;
  std::vector<ForceTorqueSensor> force_torque;
  std::vector<GroundTruthOdometry> odometry;
  std::vector<DiffDrive> diff_drives;
  // Every other <plugin> and <sensor> (cameras, controllers, ...), one
  // entry each, as IgnoredElements words it.
  std::vector<std::string> ignored;
};

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_GAZEBO_PLUGINS_H_
