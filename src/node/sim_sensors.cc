// The URDF's Gazebo sensors and plugins, run by the node: lasers, IMUs,
// bumpers, force-torque sensors, ground-truth odometry and differential
// drives. They read after each step, under the world lock, and their
// messages go out after it is released.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <geometry_msgs/WrenchStamped.h>

#include <geometry_msgs/Twist.h>

#include "node/model_sensors.h"
#include "rigid_body_sim/node/msg_conversion.h"
#include "rigid_body_sim/node/sim_node.h"

namespace rigid_body_sim::node {

using physics::Pose;
using physics::Result;
using physics::Status;
using physics::Vec3;

bool SensorClock::Due(double now) {
  if (period <= 0.0) return true;
  if (!started) {
    // The first reading, after the first step, sets the phase.
    started = true;
    next = now + period;
    return true;
  }
  // Sim time is a sum of steps: a reading due at 0.2 s must not wait a
  // step for the last bits of 48 additions of 1/240.
  if (now + 1e-9 < next) return false;
  next += period;
  if (next <= now) next = now + period;
  return true;
}

namespace {

// The link and every link below it, through fixed and movable joints.
std::vector<int> SubtreeLinks(const Model& model, const std::string& top) {
  std::vector<std::string> names{top};
  for (std::size_t i = 0; i < names.size(); ++i) {
    for (const io::JointInfo& joint : model.joints) {
      if (joint.parent_link == names[i]) names.push_back(joint.child_link);
    }
  }
  std::vector<int> links;
  for (const std::string& name : names) links.push_back(LinkIndex(model, name));
  return links;
}

// A frame a plugin names: a link of the model is its tf frame; any other
// name (odom, map) is taken as written.
std::string SensorFrame(const Model& model, const std::string& frame) {
  return LinkIndex(model, frame) >= 0 ? TfFrame(model, frame) : frame;
}

SensorClock StartClock(double rate) {
  SensorClock clock;
  clock.period = rate > 0.0 ? 1.0 / rate : 0.0;
  return clock;
}

Status UnknownLink(const io::PluginCommon& common) {
  return Status::Error("<gazebo> sensor or plugin '" + common.name + "' names link '" +
                       common.link + "', which the model does not have");
}

}  // namespace

Result<std::unique_ptr<ModelSensors>> SimNode::MakeSensorsLocked(const Model& model,
                                                                 const io::GazeboPlugins& plugins) {
  auto sensors = std::make_unique<ModelSensors>();
  if (Status status = AddLasersLocked(model, plugins, sensors.get()); !status.ok()) return status;
  if (Status status = AddInertialSensorsLocked(model, plugins, sensors.get()); !status.ok()) {
    return status;
  }
  if (Status status = AddDrivesLocked(model, plugins, sensors.get()); !status.ok()) return status;
  return sensors;
}

ros::NodeHandle SimNode::SensorHandle(const Model& model, const io::PluginCommon& common) const {
  if (!common.robot_namespace.empty()) {
    const Result<std::string> resolved = ResolveRobotNamespace(common.robot_namespace);
    if (resolved.ok()) return ros::NodeHandle(*resolved);
  }
  return model.robot_namespace.empty() ? ros::NodeHandle(private_node_, model.name)
                                       : ros::NodeHandle(model.robot_namespace);
}

Status SimNode::AddLasersLocked(const Model& model, const io::GazeboPlugins& plugins,
                                ModelSensors* sensors) {
  for (const io::LaserSensor& spec : plugins.lasers) {
    RunningLaser laser;
    laser.spec = spec;
    laser.link = LinkIndex(model, spec.common.link);
    if (laser.link < 0) return UnknownLink(spec.common);
    laser.directions_sensor = LaserDirections(spec);
    laser.frame_id = SensorFrame(model, spec.common.frame_id);
    laser.publisher = spec.point_cloud
                          ? AdvertiseSensor<sensor_msgs::PointCloud2>(model, spec.common)
                          : AdvertiseSensor<sensor_msgs::LaserScan>(model, spec.common);
    laser.clock = StartClock(spec.common.update_rate);
    sensors->lasers.push_back(std::move(laser));
  }
  return Status::Ok();
}

Status SimNode::AddInertialSensorsLocked(const Model& model, const io::GazeboPlugins& plugins,
                                         ModelSensors* sensors) {
  for (const io::ImuSensor& spec : plugins.imus) {
    RunningImu imu;
    imu.spec = spec;
    imu.link = LinkIndex(model, spec.common.link);
    if (imu.link < 0) return UnknownLink(spec.common);
    imu.frame_id = SensorFrame(model, spec.common.frame_id);
    imu.publisher = AdvertiseSensor<sensor_msgs::Imu>(model, spec.common);
    imu.clock = StartClock(spec.common.update_rate);
    imu.orientation_bias = noise_.DrawBias3(spec.orientation);
    imu.rate_bias = noise_.DrawBias3(spec.angular_velocity);
    imu.acceleration_bias = noise_.DrawBias3(spec.linear_acceleration);
    imu.before = LinkStateFromRoot(LinkStateLocked(model, imu.link), spec.common.link_from_sensor);
    sensors->imus.push_back(std::move(imu));
  }
  for (const io::BumperSensor& spec : plugins.bumpers) {
    RunningBumper bumper;
    bumper.spec = spec;
    if (LinkIndex(model, spec.common.link) < 0) return UnknownLink(spec.common);
    bumper.link_frame = FrameName(model.name, spec.common.link);
    bumper.frame_id = SensorFrame(model, spec.common.frame_id);
    bumper.publisher = AdvertiseSensor<rigid_body_sim::Contacts>(model, spec.common);
    bumper.clock = StartClock(spec.common.update_rate);
    sensors->bumpers.push_back(std::move(bumper));
  }
  for (const io::ForceTorqueSensor& spec : plugins.force_torque) {
    RunningForceTorque sensor;
    sensor.spec = spec;
    sensor.child = LinkIndex(model, spec.common.link);
    if (sensor.child < 0) return UnknownLink(spec.common);
    sensor.subtree = SubtreeLinks(model, spec.common.link);
    for (const int link : sensor.subtree) {
      sensor.subtree_frames.push_back(FrameName(model.name, model.links[link].link_name));
      sensor.before.push_back(LinkStateLocked(model, link));
    }
    sensor.frame_id = SensorFrame(model, spec.common.frame_id);
    sensor.publisher = AdvertiseSensor<geometry_msgs::WrenchStamped>(model, spec.common);
    sensor.clock = StartClock(spec.common.update_rate);
    sensors->force_torque.push_back(std::move(sensor));
  }
  for (const io::GroundTruthOdometry& spec : plugins.odometry) {
    RunningOdometry odometry;
    odometry.spec = spec;
    odometry.link = LinkIndex(model, spec.common.link);
    if (odometry.link < 0) return UnknownLink(spec.common);
    odometry.reference = spec.reference_link.empty() ? -1 : LinkIndex(model, spec.reference_link);
    odometry.frame_id =
        odometry.reference >= 0 ? TfFrame(model, spec.reference_link) : options_.world_frame;
    odometry.child_frame_id = TfFrame(model, spec.common.link);
    odometry.publisher = AdvertiseSensor<nav_msgs::Odometry>(model, spec.common);
    odometry.clock = StartClock(spec.common.update_rate);
    sensors->odometry.push_back(std::move(odometry));
  }
  return Status::Ok();
}

Status SimNode::AddDrivesLocked(const Model& model, const io::GazeboPlugins& plugins,
                                ModelSensors* sensors) {
  const auto joint_index = [&model](const std::string& name) {
    const auto found = std::find(model.joint_names.begin(), model.joint_names.end(), name);
    return found == model.joint_names.end() ? -1
                                            : static_cast<int>(found - model.joint_names.begin());
  };
  for (const io::DiffDrive& spec : plugins.diff_drives) {
    RunningDiffDrive drive;
    drive.spec = spec;
    drive.left = joint_index(spec.left_joint);
    drive.right = joint_index(spec.right_joint);
    if (drive.left < 0 || drive.right < 0 || !model.articulation.IsValid()) {
      return Status::Error("<gazebo> plugin '" + spec.common.name + "' drives joints '" +
                           spec.left_joint + "' and '" + spec.right_joint +
                           "', which must be movable joints of an articulated model");
    }
    const int base = LinkIndex(model, spec.robot_base_frame);
    drive.base = base >= 0 ? base : 0;
    drive.owns_root_tf = spec.publish_odometry && spec.publish_tf && drive.base == 0;
    drive.odom_frame = model.tf_prefix + spec.odometry_frame;
    drive.base_frame = TfFrame(model, model.links[drive.base].link_name);
    drive.command = std::make_shared<DriveCommand>();
    ros::NodeHandle handle = SensorHandle(model, spec.common);
    const std::shared_ptr<DriveCommand> command = drive.command;
    const std::string topic = spec.common.topic;
    drive.subscriber = handle.subscribe<geometry_msgs::Twist>(
        topic, 10, [this, command, topic](const geometry_msgs::Twist::ConstPtr& twist) {
          Guarded(topic.c_str(), [&] { OnDriveCommand(*twist, command.get()); });
        });
    drive.publisher = handle.advertise<nav_msgs::Odometry>(spec.odometry_topic, kSensorQueue);
    drive.clock = StartClock(spec.common.update_rate);
    sensors->drives.push_back(std::move(drive));
  }
  return Status::Ok();
}

void SimNode::OnDriveCommand(const geometry_msgs::Twist& twist, DriveCommand* command) {
  if (!std::isfinite(twist.linear.x) || !std::isfinite(twist.angular.z)) {
    ROS_ERROR("cmd_vel refused, nothing applied: linear.x %g and angular.z %g must be finite",
              twist.linear.x, twist.angular.z);
    return;
  }
  std::lock_guard<std::mutex> lock(command->mutex);
  command->linear = twist.linear.x;
  command->angular = twist.angular.z;
  command->received = true;
}

}  // namespace rigid_body_sim::node
