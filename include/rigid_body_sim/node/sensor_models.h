// What the URDF's Gazebo sensors measure, from the world's states: the
// readings of IMUs, lasers, force-torque sensors and wheel odometry, their
// seeded noise, and a differential drive's wheel commands. ROS-free; the
// node publishes the readings (sim_sensors.cc).
#ifndef RIGID_BODY_SIM_NODE_SENSOR_MODELS_H_
#define RIGID_BODY_SIM_NODE_SENSOR_MODELS_H_

#include <cstdint>
#include <random>
#include <vector>

#include "rigid_body_sim/io/gazebo_plugins.h"
#include "rigid_body_sim/node/model_registry.h"
#include "rigid_body_sim/physics/ray.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::node {

// One generator for every noisy sensor of the node, seeded by
// ~sensor_noise_seed: the same seed and the same requests give the same
// readings.
class SensorNoise {
 public:
  explicit SensorNoise(std::uint64_t seed) : engine_(seed) {}
  // A sensor's bias, drawn once: |N(bias_mean, bias_stddev^2)| with a random
  // sign, as Gazebo's GaussianNoiseModel draws it.
  double DrawBias(const io::GaussianNoise& noise);
  // value + bias + N(mean, stddev^2); no draw when the stddev is 0, so a
  // noiseless sensor leaves the sequence of the others unchanged.
  double Apply(double value, const io::GaussianNoise& noise, double bias);
  physics::Vec3 Apply(const physics::Vec3& value, const io::GaussianNoise& noise,
                      const physics::Vec3& bias);
  physics::Vec3 DrawBias3(const io::GaussianNoise& noise);

 private:
  std::mt19937_64 engine_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

// --- IMU ----------------------------------------------------------------------

struct ImuReading {
  physics::Quat world_from_sensor = physics::Quat::Identity();
  physics::Vec3 angular_velocity_sensor = physics::Vec3::Zero();  // rad/s
  // m/s^2, proper acceleration: the acceleration minus gravity, so +g up at
  // rest and 0 in free fall.
  physics::Vec3 linear_acceleration_sensor = physics::Vec3::Zero();
};

// The IMU's reading over a step of `dt` seconds from the sensor frame's
// states before and after it. The acceleration of its origin is
//   a = R d(R^T v)/dt + w x v,
// the derivative of the velocity seen in the sensor frame plus the
// transport term, with d(R^T v)/dt a finite difference over the step: exact
// for a steady turn (R^T v constant, a = w x (w x r)), for free fall (the
// integrator's v' = v + g dt) and at rest.
ImuReading MeasureImu(const FrameState& before, const FrameState& after, double dt,
                      const physics::Vec3& gravity);

// --- laser --------------------------------------------------------------------

// Ray directions of a laser in its sensor frame, vertical rows outer:
// yaw = min_angle + i (max_angle - min_angle) / (samples - 1) about z from
// x, pitch likewise from the vertical angles (0 with one vertical sample).
std::vector<physics::Vec3> LaserDirections(const io::LaserSensor& laser);
// The angle between two horizontal samples (0 for one sample), rad.
double LaserAngleIncrement(const io::LaserSensor& laser);

// The world rays of a laser at `world_from_sensor`: as Gazebo's ray sensor,
// each starts range_min out along its direction and reaches range_max.
std::vector<physics::Ray> LaserRays(const io::LaserSensor& laser,
                                    const std::vector<physics::Vec3>& directions_sensor,
                                    const physics::Pose& world_from_sensor);

// Ranges from the hits of LaserRays, as REP 117 writes them: +inf where
// nothing lies within range_max; noise (with `bias`) on each return, kept
// within [range_min, range_max], so that a return stays a return.
std::vector<double> LaserRanges(const io::LaserSensor& laser,
                                const std::vector<physics::RayHit>& hits, SensorNoise* noise);

// --- force-torque -------------------------------------------------------------

// One link below the sensor's joint: its mass and its states over the step.
struct SubtreeLink {
  double mass = 0.0;                                       // kg
  physics::Mat3 inertia_com_link = physics::Mat3::Zero();  // kg m^2, about its com, link axes
  physics::Vec3 com_link = physics::Vec3::Zero();          // m, link frame
  FrameState before;                                       // the link frame, before the step
  FrameState after;                                        // and after it
};

// A force from outside the subtree (a contact), where it acts.
struct PointForce {
  physics::Vec3 force_world = physics::Vec3::Zero();  // N
  physics::Vec3 point_world = physics::Vec3::Zero();  // m
};

struct SubtreeMotion {
  std::vector<SubtreeLink> links;
  std::vector<PointForce> external;
  physics::Vec3 point_world = physics::Vec3::Zero();  // where the wrench is taken, m
  double dt = 0.0;                                    // s, the step
  physics::Vec3 gravity = physics::Vec3::Zero();      // m/s^2
};

struct Wrench {
  physics::Vec3 force = physics::Vec3::Zero();   // N
  physics::Vec3 torque = physics::Vec3::Zero();  // N m
};

// The wrench the joint exerts on the subtree below it, at point_world, from
// Newton and Euler for each link i of the subtree:
//   F = sum_i m_i (a_i - g) - sum_k f_k
//   T = sum_i [r_i x m_i (a_i - g) + I_i alpha_i + w_i x I_i w_i] - sum_k r_k x f_k
// with r from the point to each centre of mass or force, and a_i, alpha_i
// finite differences over the step (Featherstone 2008, "Rigid Body Dynamics
// Algorithms", section 5.3: the backward pass of the recursive Newton-Euler
// algorithm, summed over the subtree).
Wrench SubtreeReaction(const SubtreeMotion& motion);

// --- differential drive -------------------------------------------------------

// Rim speeds of the two wheels (m/s) for a twist: v -+ w s / 2, left and
// right swapped in the plugin's legacy mode.
struct WheelSpeeds {
  double left = 0.0;
  double right = 0.0;
};
WheelSpeeds WheelSpeedsForTwist(const io::DiffDrive& drive, double linear, double angular);
// Moves `current` toward `target` by at most acceleration * dt (acceleration
// 0: at once), as the plugin ramps its wheels.
double RampToward(double current, double target, double acceleration, double dt);

// Planar odometry integrated from the wheels' turns (the plugin's encoder
// source): over a step the base moves ds = r (dl + dr) / 2 and turns
// dth = r (dr - dl) / s, along the arc's chord at the mid heading (exact for
// a constant-speed step).
struct PlanarOdometry {
  double x = 0.0;        // m
  double y = 0.0;        // m
  double theta = 0.0;    // rad
  double linear = 0.0;   // m/s, along the base's x
  double angular = 0.0;  // rad/s
};
void IntegrateWheels(const io::DiffDrive& drive, double left_turn, double right_turn, double dt,
                     PlanarOdometry* odometry);

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_SENSOR_MODELS_H_
