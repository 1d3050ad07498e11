// The one place where ROS message types meet the core's types. Conversions
// from messages validate what they read (finite numbers, usable quaternions)
// and fail with a message naming the field.
#ifndef RIGID_BODY_SIM_NODE_MSG_CONVERSION_H_
#define RIGID_BODY_SIM_NODE_MSG_CONVERSION_H_

#include <string>
#include <vector>

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/Vector3.h>
#include <nav_msgs/Odometry.h>
#include <ros/time.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <trajectory_msgs/JointTrajectory.h>
#include <visualization_msgs/Marker.h>
#include <visualization_msgs/MarkerArray.h>

#include "rigid_body_sim/Contact.h"
#include "rigid_body_sim/GetModelProperties.h"
#include "rigid_body_sim/PhysicsConfig.h"
#include "rigid_body_sim/Spawn.h"
#include "rigid_body_sim/node/joint_requests.h"
#include "rigid_body_sim/node/model_registry.h"
#include "rigid_body_sim/node/options.h"
#include "rigid_body_sim/node/sensor_models.h"
#include "rigid_body_sim/physics/contact.h"
#include "rigid_body_sim/physics/ray.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/shape.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::node {

// --- messages to core ---------------------------------------------------------

// Fails on a non-finite component, naming `field`.
physics::Result<physics::Vec3> VectorFromMsg(const geometry_msgs::Vector3& msg,
                                             const std::string& field);
physics::Result<physics::Vec3> PointFromMsg(const geometry_msgs::Point& msg,
                                            const std::string& field);
// Fails on a non-finite position or orientation, or a quaternion whose norm
// is outside [kMinQuaternionNorm, kMaxQuaternionNorm] (request_validation.h);
// any other quaternion is normalised.
physics::Result<physics::Pose> PoseFromMsg(const geometry_msgs::Pose& msg,
                                           const std::string& field);
physics::Result<FrameState> FrameStateFromMsg(const geometry_msgs::Pose& pose,
                                              const geometry_msgs::Twist& twist);
// The spawn request as a spec; checks the pose, the twist and that the joint
// fields pair up without repeats (the loader checks names and limits).
// The rays of a ~ray_cast request in its own frame: one per origin and
// direction (normalised), each up to max_distance. Fails naming the field
// for a count mismatch, more than physics::kMaxRaysPerCast rays, a
// non-finite origin, a zero or non-finite direction, or a max_distance
// that is not > 0.
physics::Result<std::vector<physics::Ray>> RaysFromMsg(
    const std::vector<geometry_msgs::Point>& origins,
    const std::vector<geometry_msgs::Vector3>& directions, double max_distance);
physics::Result<ModelSpec> ModelSpecFromMsg(const rigid_body_sim::Spawn::Request& request);

// The joint topics' messages as the plain requests joint_requests.h checks;
// copied as they are (the stamp is the caller's).
JointCommandRequest JointCommandFromMsg(const sensor_msgs::JointState& msg);
JointTrajectoryRequest JointTrajectoryFromMsg(const trajectory_msgs::JointTrajectory& msg);

// --- core to messages ---------------------------------------------------------

geometry_msgs::Vector3 VectorToMsg(const physics::Vec3& vector);
geometry_msgs::Point PointToMsg(const physics::Vec3& point);
geometry_msgs::Pose PoseToMsg(const physics::Pose& pose);
geometry_msgs::Twist TwistToMsg(const physics::Vec3& linear_velocity,
                                const physics::Vec3& angular_velocity);
geometry_msgs::TransformStamped TransformToMsg(const physics::Pose& parent_from_child,
                                               const std::string& parent_frame,
                                               const std::string& child_frame,
                                               const ros::Time& stamp);
// Sim time (s) as a ROS time stamp: 0 for negative or NaN, ros::TIME_MAX
// beyond its range (about 136 years), never an exception.
ros::Time SimTimeToRos(double sim_time);

rigid_body_sim::Contact ContactToMsg(const physics::ContactReport& contact,
                                     const std::string& body_a, const std::string& body_b);

// --- sensors (the caller fills the headers) ---------------------------------

// A scan of LaserRanges: the laser's angles and limits, scan_time the
// period between scans (s), intensities 0.
sensor_msgs::LaserScan LaserScanToMsg(const io::LaserSensor& laser,
                                      const std::vector<double>& ranges, double scan_time);
// The returns of a multi-row laser as points x, y, z (float32, m) in the
// sensor frame: range times direction, the rays that hit nothing left out.
sensor_msgs::PointCloud2 LaserCloudToMsg(const std::vector<physics::Vec3>& directions_sensor,
                                         const std::vector<double>& ranges);
// Covariances 0 (known), as the readings are exact but for their noise.
sensor_msgs::Imu ImuToMsg(const ImuReading& reading);
// Pose, and twist in the frame the caller chose.
nav_msgs::Odometry OdometryToMsg(const FrameState& state);

// Links with masses, joints and whether it is static (no success/message).
void ModelPropertiesToMsg(const Model& model, rigid_body_sim::GetModelProperties::Response* msg);

// --- dynamic_reconfigure (cfg/Physics.cfg) -----------------------------------

// Unchecked; ValidateLiveSettings checks.
LiveSettings LiveSettingsFromConfig(const rigid_body_sim::PhysicsConfig& config);
void LiveSettingsToConfig(const LiveSettings& settings, rigid_body_sim::PhysicsConfig* config);

// --- markers ----------------------------------------------------------------

// The collision geometry of one body, locked to `frame` (the body frame):
// a SPHERE per sphere, a TRIANGLE_LIST of the hull's faces per polyhedron
// and a thin CUBE of `half_space_size` (m) per half-space, with ids 0, 1, ...
// in namespace `ns`.
std::vector<visualization_msgs::Marker> ShapeMarkers(const std::vector<physics::ShapeDef>& shapes,
                                                     const std::string& ns,
                                                     const std::string& frame,
                                                     double half_space_size = 20.0);
// DELETE markers for ids 0 .. count-1 in namespace `ns`.
std::vector<visualization_msgs::Marker> DeleteMarkers(const std::string& ns, int count);

struct ContactMarkerStyle {
  std::string frame;  // the world frame
  ros::Time stamp;
  double force_scale = 0.02;  // m of arrow per N of normal force
  double min_arrow = 0.05;    // m, shortest arrow, so force-free contacts stay visible
  double point_size = 0.03;   // m, diameter of the point sphere
};

// Per contact i a point sphere (id 2i) and a normal arrow (id 2i+1) whose
// length is normal_force * force_scale, coloured by type (colliding red,
// resting green, separating blue). Ids from the previous array that are no
// longer used (up to 2 * previous_count) are deleted.
visualization_msgs::MarkerArray ContactMarkers(const std::vector<physics::ContactReport>& contacts,
                                               int previous_count, const ContactMarkerStyle& style);

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_MSG_CONVERSION_H_
