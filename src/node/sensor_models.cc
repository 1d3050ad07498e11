#include "rigid_body_sim/node/sensor_models.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rigid_body_sim::node {

using physics::Pose;
using physics::Quat;
using physics::Vec3;

double SensorNoise::DrawBias(const io::GaussianNoise& noise) {
  if (noise.bias_mean == 0.0 && noise.bias_stddev == 0.0) return 0.0;
  const double magnitude = noise.bias_mean + noise.bias_stddev * normal_(engine_);
  // Gazebo flips the bias's sign with probability one half: a bias of known
  // size but unknown direction.
  return std::uniform_int_distribution<int>(0, 1)(engine_) == 0 ? magnitude : -magnitude;
}

Vec3 SensorNoise::DrawBias3(const io::GaussianNoise& noise) {
  Vec3 bias;
  for (int axis = 0; axis < 3; ++axis) bias[axis] = DrawBias(noise);
  return bias;
}

double SensorNoise::Apply(double value, const io::GaussianNoise& noise, double bias) {
  const double draw = noise.stddev > 0.0 ? noise.stddev * normal_(engine_) : 0.0;
  return value + bias + noise.mean + draw;
}

Vec3 SensorNoise::Apply(const Vec3& value, const io::GaussianNoise& noise, const Vec3& bias) {
  Vec3 noisy;
  for (int axis = 0; axis < 3; ++axis) noisy[axis] = Apply(value[axis], noise, bias[axis]);
  return noisy;
}

ImuReading MeasureImu(const FrameState& before, const FrameState& after, double dt,
                      const Vec3& gravity) {
  const Quat& q_before = before.world_from_frame.rotation;
  const Quat& q_after = after.world_from_frame.rotation;
  const Vec3 velocity_in_sensor_before = q_before.conjugate() * before.linear_velocity;
  const Vec3 velocity_in_sensor_after = q_after.conjugate() * after.linear_velocity;
  const Vec3 seen_change = (velocity_in_sensor_after - velocity_in_sensor_before) / dt;
  const Vec3 transport_world = after.angular_velocity.cross(after.linear_velocity);
  ImuReading reading;
  reading.world_from_sensor = q_after;
  reading.angular_velocity_sensor = q_after.conjugate() * after.angular_velocity;
  reading.linear_acceleration_sensor =
      seen_change + q_after.conjugate() * (transport_world - gravity);
  return reading;
}

namespace {

double Step(double low, double high, int samples) {
  return samples > 1 ? (high - low) / (samples - 1) : 0.0;
}

}  // namespace

double LaserAngleIncrement(const io::LaserSensor& laser) {
  return Step(laser.min_angle, laser.max_angle, laser.horizontal_samples);
}

std::vector<Vec3> LaserDirections(const io::LaserSensor& laser) {
  std::vector<Vec3> directions;
  directions.reserve(static_cast<std::size_t>(laser.horizontal_samples) * laser.vertical_samples);
  const double yaw_step = LaserAngleIncrement(laser);
  const double pitch_step =
      Step(laser.vertical_min_angle, laser.vertical_max_angle, laser.vertical_samples);
  for (int row = 0; row < laser.vertical_samples; ++row) {
    const double pitch =
        laser.vertical_samples > 1 ? laser.vertical_min_angle + row * pitch_step : 0.0;
    for (int column = 0; column < laser.horizontal_samples; ++column) {
      const double yaw = laser.min_angle + column * yaw_step;
      directions.emplace_back(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                              std::sin(pitch));
    }
  }
  return directions;
}

std::vector<physics::Ray> LaserRays(const io::LaserSensor& laser,
                                    const std::vector<Vec3>& directions_sensor,
                                    const Pose& world_from_sensor) {
  std::vector<physics::Ray> rays;
  rays.reserve(directions_sensor.size());
  for (const Vec3& direction_sensor : directions_sensor) {
    physics::Ray ray;
    ray.direction = world_from_sensor.rotation * direction_sensor;
    ray.origin = world_from_sensor.translation + laser.range_min * ray.direction;
    ray.max_distance = laser.range_max - laser.range_min;
    rays.push_back(ray);
  }
  return rays;
}

std::vector<double> LaserRanges(const io::LaserSensor& laser,
                                const std::vector<physics::RayHit>& hits, SensorNoise* noise) {
  std::vector<double> ranges;
  ranges.reserve(hits.size());
  for (const physics::RayHit& hit : hits) {
    if (!hit.hit) {
      ranges.push_back(std::numeric_limits<double>::infinity());
      continue;
    }
    const double range = laser.range_min + hit.distance;
    const double noisy = noise->Apply(range, laser.noise, 0.0);
    ranges.push_back(std::clamp(noisy, laser.range_min, laser.range_max));
  }
  return ranges;
}

Wrench SubtreeReaction(const SubtreeMotion& motion) {
  Wrench wrench;
  for (const SubtreeLink& link : motion.links) {
    const Pose link_from_com{link.com_link, Quat::Identity()};
    const FrameState com_before = LinkStateFromRoot(link.before, link_from_com);
    const FrameState com_after = LinkStateFromRoot(link.after, link_from_com);
    const Vec3 acceleration = (com_after.linear_velocity - com_before.linear_velocity) / motion.dt;
    const Vec3 alpha = (com_after.angular_velocity - com_before.angular_velocity) / motion.dt;
    const physics::Mat3 rotation = link.after.world_from_frame.rotation.toRotationMatrix();
    const physics::Mat3 inertia_world = rotation * link.inertia_com_link * rotation.transpose();
    const Vec3& w = com_after.angular_velocity;
    const Vec3 force = link.mass * (acceleration - motion.gravity);
    const Vec3 lever = com_after.world_from_frame.translation - motion.point_world;
    wrench.force += force;
    wrench.torque += lever.cross(force) + inertia_world * alpha + w.cross(inertia_world * w);
  }
  for (const PointForce& external : motion.external) {
    wrench.force -= external.force_world;
    wrench.torque -= (external.point_world - motion.point_world).cross(external.force_world);
  }
  return wrench;
}

WheelSpeeds WheelSpeedsForTwist(const io::DiffDrive& drive, double linear, double angular) {
  const double turn = angular * drive.wheel_separation / 2.0;
  WheelSpeeds speeds{linear - turn, linear + turn};
  if (drive.legacy_mode) std::swap(speeds.left, speeds.right);
  return speeds;
}

double RampToward(double current, double target, double acceleration, double dt) {
  if (acceleration <= 0.0) return target;
  const double reach = acceleration * dt;
  return current + std::clamp(target - current, -reach, reach);
}

void IntegrateWheels(const io::DiffDrive& drive, double left_turn, double right_turn, double dt,
                     PlanarOdometry* odometry) {
  const double radius = drive.wheel_diameter / 2.0;
  const double distance = radius * (left_turn + right_turn) / 2.0;
  const double turn = radius * (right_turn - left_turn) / drive.wheel_separation;
  // The chord of an arc of angle dth and length ds has length
  // ds sin(dth/2) / (dth/2) and points along the mid heading.
  const double half = turn / 2.0;
  const double chord = std::abs(half) > 1e-9 ? distance * std::sin(half) / half : distance;
  const double heading = odometry->theta + half;
  odometry->x += chord * std::cos(heading);
  odometry->y += chord * std::sin(heading);
  odometry->theta = std::remainder(odometry->theta + turn, 2.0 * M_PI);
  odometry->linear = dt > 0.0 ? distance / dt : 0.0;
  odometry->angular = dt > 0.0 ? turn / dt : 0.0;
}

}  // namespace rigid_body_sim::node
