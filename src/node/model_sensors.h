// The running sensors and plugins of one spawned model: their topics, their
// clocks and what they carry from one step to the next. The node keeps them
// under the world mutex (sim_sensors.cc).
#ifndef RIGID_BODY_SIM_NODE_MODEL_SENSORS_H_
#define RIGID_BODY_SIM_NODE_MODEL_SENSORS_H_

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "rigid_body_sim/io/gazebo_plugins.h"
#include "rigid_body_sim/node/model_registry.h"
#include "rigid_body_sim/node/sensor_models.h"

namespace rigid_body_sim::node {

// When a sensor reads: after the first step, then every `period` seconds
// of sim time, or after every step for a period of 0 (an <update_rate> of
// 0).
struct SensorClock {
  double period = 0.0;   // s
  double next = 0.0;     // sim time of the next reading, s
  bool started = false;  // read once since spawn or reset
  // Whether a reading is due at `now`; if so `next` moves on by a period,
  // or to a period after `now` when the sensor fell behind (a reset).
  bool Due(double now);
};

struct RunningLaser {
  io::LaserSensor spec;
  int link = 0;  // index into Model::links
  std::vector<physics::Vec3> directions_sensor;
  std::string frame_id;
  ros::Publisher publisher;
  SensorClock clock;
};

struct RunningImu {
  io::ImuSensor spec;
  int link = 0;
  std::string frame_id;
  ros::Publisher publisher;
  SensorClock clock;
  FrameState before;  // the sensor frame before the step
  physics::Vec3 orientation_bias = physics::Vec3::Zero();
  physics::Vec3 rate_bias = physics::Vec3::Zero();
  physics::Vec3 acceleration_bias = physics::Vec3::Zero();
};

struct RunningBumper {
  io::BumperSensor spec;
  std::string link_frame;  // FrameName(model, link): how contacts name it
  std::string frame_id;
  ros::Publisher publisher;
  SensorClock clock;
};

struct RunningForceTorque {
  io::ForceTorqueSensor spec;
  int child = 0;                            // the joint's child link
  std::vector<int> subtree;                 // the child and every link below it
  std::vector<std::string> subtree_frames;  // FrameName of each
  std::vector<FrameState> before;           // per subtree link, before the step
  std::string frame_id;
  ros::Publisher publisher;
  SensorClock clock;
};

struct RunningOdometry {
  io::GroundTruthOdometry spec;
  int link = 0;
  int reference = -1;  // a link of the model, or -1 for the world frame
  std::string frame_id;
  std::string child_frame_id;
  ros::Publisher publisher;
  SensorClock clock;
};

// The latest cmd_vel; written by its subscriber without the world lock, so
// that destroying the subscriber under the lock cannot wait on it.
struct DriveCommand {
  std::mutex mutex;
  double linear = 0.0;   // m/s
  double angular = 0.0;  // rad/s
  bool received = false;
};

struct RunningDiffDrive {
  io::DiffDrive spec;
  int left = 0;  // index into Model::joint_names
  int right = 0;
  int base = 0;  // the link of robot_base_frame (the root when it names none)
  std::shared_ptr<DriveCommand> command;
  ros::Subscriber subscriber;
  ros::Publisher publisher;
  SensorClock clock;
  WheelSpeeds wheels;  // rim speeds commanded last step, m/s
  PlanarOdometry encoder;
  // rad, the wheels' positions before the step (DriveWheelsLocked reads
  // them then, so a reset or ~set_joint_state between steps is no turn).
  double left_before = 0.0;
  double right_before = 0.0;
  // The odom -> base tf replaces the node's world -> root: the base is the
  // root link and publish_tf is set.
  bool owns_root_tf = false;
  std::string odom_frame;
  std::string base_frame;
};

struct ModelSensors {
  ros::NodeHandle handle;  // the sensors' robot namespace
  std::vector<RunningLaser> lasers;
  std::vector<RunningImu> imus;
  std::vector<RunningBumper> bumpers;
  std::vector<RunningForceTorque> force_torque;
  std::vector<RunningOdometry> odometry;
  std::vector<RunningDiffDrive> drives;
  bool empty() const {
    return lasers.empty() && imus.empty() && bumpers.empty() && force_torque.empty() &&
           odometry.empty() && drives.empty();
  }
};

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_MODEL_SENSORS_H_
