// The readings of the models' sensors around each step: the drives command
// their wheels before it, every sensor that is due reads after it, and the
// messages wait in pending_sensor_messages_ until the world lock is
// released.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <geometry_msgs/WrenchStamped.h>

#include "node/model_sensors.h"
#include "rigid_body_sim/node/msg_conversion.h"
#include "rigid_body_sim/node/sim_node.h"

namespace rigid_body_sim::node {

using physics::Pose;
using physics::Quat;
using physics::Vec3;

namespace {

// Queues `message` for `publisher`, to go out when the lock is released.
template <typename Message>
std::function<void()> Deferred(const ros::Publisher& publisher, Message message) {
  auto shared = std::make_shared<Message>(std::move(message));
  return [publisher, shared] { publisher.publish(*shared); };
}

}  // namespace

void SimNode::BeforeStepSensorsLocked() {
  const double dt = world_.settings().time_step;
  for (auto& [name, sensors] : sensors_) {
    const Model* model = registry_.Find(name);
    if (model == nullptr) continue;
    for (RunningImu& imu : sensors->imus) {
      imu.before =
          LinkStateFromRoot(LinkStateLocked(*model, imu.link), imu.spec.common.link_from_sensor);
    }
    for (RunningForceTorque& sensor : sensors->force_torque) {
      for (std::size_t i = 0; i < sensor.subtree.size(); ++i) {
        sensor.before[i] = LinkStateLocked(*model, sensor.subtree[i]);
      }
    }
    for (RunningDiffDrive& drive : sensors->drives) DriveWheelsLocked(*model, dt, &drive);
  }
}

// The plugin's loop: the wheels' rim speeds ramp toward those of the last
// cmd_vel, and each wheel is a velocity motor capped at wheelTorque.
void SimNode::DriveWheelsLocked(const Model& model, double dt, RunningDiffDrive* drive) {
  const std::vector<physics::JointState> joints = world_.GetJointStates(model.articulation);
  drive->left_before = joints[drive->left].position;
  drive->right_before = joints[drive->right].position;
  double linear = 0.0;
  double angular = 0.0;
  {
    std::lock_guard<std::mutex> lock(drive->command->mutex);
    if (!drive->command->received) return;
    linear = drive->command->linear;
    angular = drive->command->angular;
  }
  const WheelSpeeds target = WheelSpeedsForTwist(drive->spec, linear, angular);
  drive->wheels.left =
      RampToward(drive->wheels.left, target.left, drive->spec.wheel_acceleration, dt);
  drive->wheels.right =
      RampToward(drive->wheels.right, target.right, drive->spec.wheel_acceleration, dt);
  const double radius = drive->spec.wheel_diameter / 2.0;
  const auto command = [&](int joint, double rim_speed) {
    physics::JointCommand motor;
    motor.mode = physics::JointCommandMode::kVelocity;
    motor.velocity = rim_speed / radius;
    motor.max_effort = drive->spec.wheel_torque;
    const physics::Status status = world_.SetJointCommand(model.articulation, joint, motor);
    if (!status.ok())
      ROS_ERROR_THROTTLE(5.0, "%s: %s", model.name.c_str(), status.message().c_str());
  };
  command(drive->left, drive->wheels.left);
  command(drive->right, drive->wheels.right);
}

void SimNode::AfterStepSensorsLocked() {
  const double now = world_.time();
  const ros::Time stamp = StampLocked();
  for (auto& [name, sensors] : sensors_) {
    const Model* model = registry_.Find(name);
    if (model == nullptr) continue;
    for (RunningLaser& laser : sensors->lasers) {
      if (laser.clock.Due(now)) ReadLaserLocked(*model, stamp, &laser);
    }
    for (RunningImu& imu : sensors->imus) {
      if (imu.clock.Due(now)) ReadImuLocked(*model, stamp, &imu);
    }
    for (RunningBumper& bumper : sensors->bumpers) {
      if (bumper.clock.Due(now)) ReadBumperLocked(stamp, bumper);
    }
    for (RunningForceTorque& sensor : sensors->force_torque) {
      if (sensor.clock.Due(now)) ReadForceTorqueLocked(*model, stamp, sensor);
    }
    for (RunningOdometry& odometry : sensors->odometry) {
      if (odometry.clock.Due(now)) ReadGroundTruthLocked(*model, stamp, odometry);
    }
    for (RunningDiffDrive& drive : sensors->drives) ReadDriveOdometryLocked(*model, stamp, &drive);
  }
}

void SimNode::ReadLaserLocked(const Model& model, const ros::Time& stamp, RunningLaser* laser) {
  const Pose world_from_sensor =
      LinkStateLocked(model, laser->link).world_from_frame * laser->spec.common.link_from_sensor;
  // A laser never sees the inside of the body that carries it (Gazebo's
  // rays start at range_min for the same reason).
  const std::vector<physics::BodyId> own{model.bodies[model.link_body[laser->link]]};
  const auto hits =
      world_.CastRays(LaserRays(laser->spec, laser->directions_sensor, world_from_sensor), own);
  if (!hits.ok()) {
    ROS_ERROR_THROTTLE(5.0, "laser '%s': %s", laser->spec.common.name.c_str(),
                       hits.message().c_str());
    return;
  }
  const std::vector<double> ranges = LaserRanges(laser->spec, *hits, &noise_);
  const double period =
      laser->clock.period > 0.0 ? laser->clock.period : world_.settings().time_step;
  if (laser->spec.point_cloud) {
    sensor_msgs::PointCloud2 cloud = LaserCloudToMsg(laser->directions_sensor, ranges);
    cloud.header.stamp = stamp;
    cloud.header.frame_id = laser->frame_id;
    pending_sensor_messages_.push_back(Deferred(laser->publisher, std::move(cloud)));
    return;
  }
  sensor_msgs::LaserScan scan = LaserScanToMsg(laser->spec, ranges, period);
  scan.header.stamp = stamp;
  scan.header.frame_id = laser->frame_id;
  pending_sensor_messages_.push_back(Deferred(laser->publisher, std::move(scan)));
}

void SimNode::ReadImuLocked(const Model& model, const ros::Time& stamp, RunningImu* imu) {
  const FrameState after =
      LinkStateFromRoot(LinkStateLocked(model, imu->link), imu->spec.common.link_from_sensor);
  ImuReading reading =
      MeasureImu(imu->before, after, world_.settings().time_step, world_.settings().gravity);
  reading.world_from_sensor = imu->spec.orientation_offset * reading.world_from_sensor;
  const Vec3 tilt = noise_.Apply(Vec3::Zero(), imu->spec.orientation, imu->orientation_bias);
  if (!tilt.isZero()) {
    reading.world_from_sensor =
        reading.world_from_sensor * Quat(Eigen::AngleAxisd(tilt.norm(), tilt.normalized()));
  }
  reading.angular_velocity_sensor =
      noise_.Apply(reading.angular_velocity_sensor, imu->spec.angular_velocity, imu->rate_bias);
  reading.linear_acceleration_sensor = noise_.Apply(
      reading.linear_acceleration_sensor, imu->spec.linear_acceleration, imu->acceleration_bias);
  sensor_msgs::Imu message = ImuToMsg(reading);
  message.header.stamp = stamp;
  message.header.frame_id = imu->frame_id;
  pending_sensor_messages_.push_back(Deferred(imu->publisher, std::move(message)));
}

void SimNode::ReadBumperLocked(const ros::Time& stamp, const RunningBumper& bumper) {
  rigid_body_sim::Contacts message;
  message.header.stamp = stamp;
  message.header.frame_id = options_.world_frame;
  for (const physics::ContactReport& contact : world_.contacts()) {
    const std::string a = registry_.ShapeFrame(contact.body_a, contact.shape_a);
    const std::string b = registry_.ShapeFrame(contact.body_b, contact.shape_b);
    const std::string other_a = a.empty() ? "ground" : a;
    const std::string other_b = b.empty() ? "ground" : b;
    if (a == bumper.link_frame) {
      message.contacts.push_back(ContactToMsg(contact, a, other_b));
    } else if (b == bumper.link_frame) {
      // Seen from the bumper's link: it is body_a, the normal points at it.
      physics::ContactReport flipped = contact;
      flipped.normal_world = -contact.normal_world;
      flipped.friction_impulse_world = -contact.friction_impulse_world;
      message.contacts.push_back(ContactToMsg(flipped, b, other_a));
    }
  }
  pending_sensor_messages_.push_back(Deferred(bumper.publisher, std::move(message)));
}

void SimNode::ReadForceTorqueLocked(const Model& model, const ros::Time& stamp,
                                    const RunningForceTorque& sensor) {
  const double dt = world_.settings().time_step;
  SubtreeMotion motion;
  motion.dt = dt;
  motion.gravity = world_.settings().gravity;
  const FrameState child = LinkStateLocked(model, sensor.child);
  motion.point_world = child.world_from_frame.translation;
  for (std::size_t i = 0; i < sensor.subtree.size(); ++i) {
    const io::LinkFrame& link = model.links[sensor.subtree[i]];
    SubtreeLink entry;
    entry.mass = link.mass_in_link.mass;
    entry.com_link = link.mass_in_link.center_of_mass;
    entry.inertia_com_link = link.mass_in_link.inertia_about_com;
    entry.before = sensor.before[i];
    entry.after = LinkStateLocked(model, sensor.subtree[i]);
    motion.links.push_back(entry);
  }
  // Contacts on the subtree's links push on it from outside.
  for (const physics::ContactReport& contact : world_.contacts()) {
    const Vec3 on_a =
        contact.normal_force * contact.normal_world + contact.friction_impulse_world / dt;
    const auto in_subtree = [&sensor](const std::string& frame) {
      return std::find(sensor.subtree_frames.begin(), sensor.subtree_frames.end(), frame) !=
             sensor.subtree_frames.end();
    };
    if (in_subtree(registry_.ShapeFrame(contact.body_a, contact.shape_a))) {
      motion.external.push_back({on_a, contact.position_world});
    }
    if (in_subtree(registry_.ShapeFrame(contact.body_b, contact.shape_b))) {
      motion.external.push_back({-on_a, contact.position_world});
    }
  }
  const Wrench world_wrench = SubtreeReaction(motion);
  const Quat child_from_world = child.world_from_frame.rotation.conjugate();
  Wrench wrench{child_from_world * world_wrench.force, child_from_world * world_wrench.torque};
  wrench.force = noise_.Apply(wrench.force, sensor.spec.noise, Vec3::Zero());
  wrench.torque = noise_.Apply(wrench.torque, sensor.spec.noise, Vec3::Zero());
  geometry_msgs::WrenchStamped message;
  message.header.stamp = stamp;
  message.header.frame_id = sensor.frame_id;
  message.wrench.force = VectorToMsg(wrench.force);
  message.wrench.torque = VectorToMsg(wrench.torque);
  pending_sensor_messages_.push_back(Deferred(sensor.publisher, std::move(message)));
}

void SimNode::ReadGroundTruthLocked(const Model& model, const ros::Time& stamp,
                                    const RunningOdometry& odometry) {
  const FrameState body = LinkStateFromRoot(LinkStateLocked(model, odometry.link),
                                            odometry.spec.common.link_from_sensor);
  FrameState relative = body;
  if (odometry.reference >= 0) {
    // As the plugin: the pose in the reference link's frame and the
    // difference of the two frames' velocities in its axes.
    const FrameState reference = LinkStateLocked(model, odometry.reference);
    const Pose reference_from_world = reference.world_from_frame.Inverse();
    relative.world_from_frame = reference_from_world * body.world_from_frame;
    relative.linear_velocity =
        reference_from_world.rotation * (body.linear_velocity - reference.linear_velocity);
    relative.angular_velocity =
        reference_from_world.rotation * (body.angular_velocity - reference.angular_velocity);
  }
  relative.world_from_frame.translation += odometry.spec.offset.translation;
  relative.world_from_frame.rotation =
      odometry.spec.offset.rotation * relative.world_from_frame.rotation;
  const io::GaussianNoise& noise = odometry.spec.noise;
  relative.world_from_frame.translation =
      noise_.Apply(relative.world_from_frame.translation, noise, Vec3::Zero());
  relative.linear_velocity = noise_.Apply(relative.linear_velocity, noise, Vec3::Zero());
  relative.angular_velocity = noise_.Apply(relative.angular_velocity, noise, Vec3::Zero());
  nav_msgs::Odometry message = OdometryToMsg(relative);
  message.header.stamp = stamp;
  message.header.frame_id = odometry.frame_id;
  message.child_frame_id = odometry.child_frame_id;
  pending_sensor_messages_.push_back(Deferred(odometry.publisher, std::move(message)));
}

// Encoder odometry integrates every step; the message goes out at the
// plugin's rate, from the encoders or from the world (the base's true pose,
// its velocity in the base's heading frame, as the plugin reports it).
void SimNode::ReadDriveOdometryLocked(const Model& model, const ros::Time& stamp,
                                      RunningDiffDrive* drive) {
  const double dt = world_.settings().time_step;
  const std::vector<physics::JointState> joints = world_.GetJointStates(model.articulation);
  IntegrateWheels(drive->spec, joints[drive->left].position - drive->left_before,
                  joints[drive->right].position - drive->right_before, dt, &drive->encoder);
  if (!drive->spec.publish_odometry || !drive->clock.Due(world_.time())) return;
  nav_msgs::Odometry message = OdometryToMsg(DriveOdometryLocked(model, *drive));
  if (!drive->spec.odometry_from_encoders) {
    // The plugin's world source reports the twist in the base's frame.
    const FrameState base = LinkStateLocked(model, drive->base);
    const Quat base_from_world = base.world_from_frame.rotation.conjugate();
    message.twist.twist =
        TwistToMsg(base_from_world * base.linear_velocity, base_from_world * base.angular_velocity);
  }
  message.header.stamp = stamp;
  message.header.frame_id = drive->odom_frame;
  message.child_frame_id = drive->base_frame;
  pending_sensor_messages_.push_back(Deferred(drive->publisher, std::move(message)));
}

FrameState SimNode::DriveOdometryLocked(const Model& model, const RunningDiffDrive& drive) const {
  if (!drive.spec.odometry_from_encoders) return LinkStateLocked(model, drive.base);
  const PlanarOdometry& encoder = drive.encoder;
  FrameState odometry;
  odometry.world_from_frame.translation = Vec3(encoder.x, encoder.y, 0.0);
  odometry.world_from_frame.rotation = Quat(Eigen::AngleAxisd(encoder.theta, Vec3::UnitZ()));
  odometry.linear_velocity = Vec3(encoder.linear, 0.0, 0.0);
  odometry.angular_velocity = Vec3(0.0, 0.0, encoder.angular);
  return odometry;
}

const RunningDiffDrive* SimNode::RootTfDriveLocked(const Model& model) const {
  const auto found = sensors_.find(model.name);
  if (found == sensors_.end()) return nullptr;
  for (const RunningDiffDrive& drive : found->second->drives) {
    if (drive.owns_root_tf) return &drive;
  }
  return nullptr;
}

// odom -> root is the drive's odometry, and world -> odom what puts the
// root where it truly is: world_from_odom = world_from_root odom_from_root^-1
// (the identity for the world source; the encoders' drift otherwise, as a
// localiser's map -> odom).
void SimNode::AppendDriveTfLocked(const Model& model, const RunningDiffDrive& drive,
                                  const ros::Time& stamp, tf2_msgs::TFMessage* tf) const {
  const Pose world_from_root = LinkStateLocked(model, 0).world_from_frame;
  const Pose odom_from_root = DriveOdometryLocked(model, drive).world_from_frame;
  tf->transforms.push_back(TransformToMsg(world_from_root * odom_from_root.Inverse(),
                                          options_.world_frame, drive.odom_frame, stamp));
  tf->transforms.push_back(
      TransformToMsg(odom_from_root, drive.odom_frame, drive.base_frame, stamp));
}

void SimNode::ResetSensorsLocked() {
  for (auto& [name, sensors] : sensors_) {
    const Model* model = registry_.Find(name);
    if (model == nullptr) continue;
    for (RunningLaser& laser : sensors->lasers) laser.clock.started = false;
    for (RunningImu& imu : sensors->imus) {
      imu.clock.started = false;
      imu.before =
          LinkStateFromRoot(LinkStateLocked(*model, imu.link), imu.spec.common.link_from_sensor);
    }
    for (RunningBumper& bumper : sensors->bumpers) bumper.clock.started = false;
    for (RunningForceTorque& sensor : sensors->force_torque) sensor.clock.started = false;
    for (RunningOdometry& odometry : sensors->odometry) odometry.clock.started = false;
    for (RunningDiffDrive& drive : sensors->drives) {
      drive.clock.started = false;
      drive.encoder = PlanarOdometry();
      drive.wheels = WheelSpeeds();
      std::lock_guard<std::mutex> lock(drive.command->mutex);
      drive.command->received = false;
    }
  }
}

}  // namespace rigid_body_sim::node
