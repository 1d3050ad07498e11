#include "rigid_body_sim/node/msg_conversion.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <variant>

#include "rigid_body_sim/node/request_validation.h"

namespace rigid_body_sim::node {

using physics::Pose;
using physics::Quat;
using physics::Result;
using physics::Status;
using physics::Vec3;

namespace {

std_msgs::ColorRGBA Color(float r, float g, float b, float a) {
  std_msgs::ColorRGBA color;
  color.r = r;
  color.g = g;
  color.b = b;
  color.a = a;
  return color;
}

visualization_msgs::Marker BaseMarker(const std::string& ns, int id, const std::string& frame) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame;
  marker.ns = ns;
  marker.id = id;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.orientation.w = 1.0;
  return marker;
}

}  // namespace

namespace {

std::string Describe(const Vec3& v) {
  return "[" + physics::FormatNumber(v.x()) + ", " + physics::FormatNumber(v.y()) + ", " +
         physics::FormatNumber(v.z()) + "]";
}

}  // namespace

Result<Vec3> VectorFromMsg(const geometry_msgs::Vector3& msg, const std::string& field) {
  const Vec3 vector(msg.x, msg.y, msg.z);
  if (!vector.allFinite()) {
    return Result<Vec3>::Error(field + " " + Describe(vector) + " is not finite");
  }
  return vector;
}

Result<Vec3> PointFromMsg(const geometry_msgs::Point& msg, const std::string& field) {
  const Vec3 point(msg.x, msg.y, msg.z);
  if (!point.allFinite()) {
    return Result<Vec3>::Error(field + " " + Describe(point) + " is not finite");
  }
  return point;
}

Result<Pose> PoseFromMsg(const geometry_msgs::Pose& msg, const std::string& field) {
  Result<Vec3> position = PointFromMsg(msg.position, field + ".position");
  if (!position.ok()) return position.status();
  Quat rotation(msg.orientation.w, msg.orientation.x, msg.orientation.y, msg.orientation.z);
  const std::string shown =
      field + ".orientation (w, x, y, z) = (" + physics::FormatNumber(rotation.w()) + ", " +
      physics::FormatNumber(rotation.x()) + ", " + physics::FormatNumber(rotation.y()) + ", " +
      physics::FormatNumber(rotation.z()) + ")";
  if (!rotation.coeffs().allFinite()) return Result<Pose>::Error(shown + " is not finite");
  // stableNorm: a quaternion of 1e200s has a finite norm that norm() would
  // overflow, and normalising by infinity would leave a zero quaternion.
  const double norm = rotation.coeffs().stableNorm();
  const std::string range = " outside the allowed range [" +
                            physics::FormatNumber(kMinQuaternionNorm) + ", " +
                            physics::FormatNumber(kMaxQuaternionNorm) + "]";
  if (norm < kMinQuaternionNorm) {
    return Result<Pose>::Error(shown + " is a zero quaternion: norm " +
                               physics::FormatNumber(norm) + range);
  }
  if (!(norm <= kMaxQuaternionNorm)) {
    return Result<Pose>::Error(shown + " has norm " + physics::FormatNumber(norm) + range);
  }
  rotation.coeffs() /= norm;
  return Pose{*position, rotation};
}

Result<FrameState> FrameStateFromMsg(const geometry_msgs::Pose& pose,
                                     const geometry_msgs::Twist& twist) {
  Result<Pose> world_from_frame = PoseFromMsg(pose, "pose");
  if (!world_from_frame.ok()) return world_from_frame.status();
  Result<Vec3> linear = VectorFromMsg(twist.linear, "twist.linear");
  if (!linear.ok()) return linear.status();
  Result<Vec3> angular = VectorFromMsg(twist.angular, "twist.angular");
  if (!angular.ok()) return angular.status();
  return FrameState{*world_from_frame, *linear, *angular};
}

Result<std::vector<physics::Ray>> RaysFromMsg(const std::vector<geometry_msgs::Point>& origins,
                                              const std::vector<geometry_msgs::Vector3>& directions,
                                              double max_distance) {
  using Rays = Result<std::vector<physics::Ray>>;
  if (origins.size() != directions.size()) {
    return Rays::Error("origins has " + std::to_string(origins.size()) + " entries, directions " +
                       std::to_string(directions.size()) + "; they must match");
  }
  if (origins.size() > physics::kMaxRaysPerCast) {
    return Rays::Error("origins has " + std::to_string(origins.size()) +
                       " rays, more than the limit " + std::to_string(physics::kMaxRaysPerCast));
  }
  if (!(max_distance > 0.0)) {
    return Rays::Error("max_distance " + physics::FormatNumber(max_distance) +
                       " m must be > 0 (inf for no limit)");
  }
  std::vector<physics::Ray> rays(origins.size());
  for (std::size_t i = 0; i < origins.size(); ++i) {
    const Vec3 origin(origins[i].x, origins[i].y, origins[i].z);
    const Vec3 direction(directions[i].x, directions[i].y, directions[i].z);
    // A direction whose norm underflows or overflows cannot be normalised.
    const double length = direction.norm();
    if (origin.allFinite() && direction.allFinite() && length > 0.0 && std::isfinite(length)) {
      rays[i] = physics::Ray{origin, direction / length, max_distance};
      continue;
    }
    // The field's name is formatted only for a bad ray: formatted for each
    // of 100,000 good rays, it was 8 % of a ray_cast call's time.
    const std::string index = "[" + std::to_string(i) + "]";
    Result<Vec3> checked = PointFromMsg(origins[i], "origins" + index);
    if (!checked.ok()) return checked.status();
    checked = VectorFromMsg(directions[i], "directions" + index);
    if (!checked.ok()) return checked.status();
    return Rays::Error("directions" + index + " " + Describe(direction) +
                       " has no direction (length " + physics::FormatNumber(length) + ")");
  }
  return rays;
}

Result<ModelSpec> ModelSpecFromMsg(const rigid_body_sim::Spawn::Request& request) {
  Result<FrameState> state = FrameStateFromMsg(request.pose, request.twist);
  if (!state.ok()) return state.status();
  ModelSpec spec;
  spec.name = request.name;
  spec.urdf = request.urdf;
  spec.urdf_path = request.urdf_path;
  spec.root_state = *state;
  spec.is_static = request.is_static;
  spec.friction = request.friction;
  spec.restitution = request.restitution;
  spec.self_collide = request.self_collide;
  spec.robot_namespace = request.robot_namespace;
  spec.tf_prefix = request.tf_prefix;
  Result<TfMode> tf_mode = TfModeFromName(request.tf_mode);
  if (!tf_mode.ok()) return tf_mode.status();
  spec.tf_mode = *tf_mode;
  spec.hold = request.hold;
  spec.xacro_args = request.xacro_args;
  if (request.joint_positions.size() != request.joint_names.size()) {
    return Result<ModelSpec>::Error(
        "joint_positions has " + std::to_string(request.joint_positions.size()) + " values for " +
        std::to_string(request.joint_names.size()) + " joint_names");
  }
  for (std::size_t i = 0; i < request.joint_names.size(); ++i) {
    const std::string& name = request.joint_names[i];
    if (!spec.joint_positions.emplace(name, request.joint_positions[i]).second) {
      return Result<ModelSpec>::Error("joint_names[" + std::to_string(i) + "] '" + name +
                                      "' is given twice");
    }
  }
  return spec;
}

void ModelPropertiesToMsg(const Model& model, rigid_body_sim::GetModelProperties::Response* msg) {
  msg->root_link = model.links.front().link_name;
  for (const io::LinkFrame& link : model.links) {
    msg->link_names.push_back(link.link_name);
    msg->link_masses.push_back(link.mass);
  }
  msg->mass = model.mass;
  for (const io::JointInfo& joint : model.joints) {
    msg->joint_names.push_back(joint.name);
    msg->joint_types.push_back(joint.type);
    msg->joint_positions.push_back(joint.position);
  }
  msg->is_static = model.is_static;
}

JointCommandRequest JointCommandFromMsg(const sensor_msgs::JointState& msg) {
  return JointCommandRequest{msg.name, msg.position, msg.velocity, msg.effort};
}

JointTrajectoryRequest JointTrajectoryFromMsg(const trajectory_msgs::JointTrajectory& msg) {
  JointTrajectoryRequest request;
  request.joint_names = msg.joint_names;
  request.points.reserve(msg.points.size());
  for (const trajectory_msgs::JointTrajectoryPoint& point : msg.points) {
    // toSec is sec + 1e-9 nsec in double: no range to leave.
    request.points.push_back({point.positions, point.velocities, point.time_from_start.toSec()});
  }
  return request;
}

geometry_msgs::Vector3 VectorToMsg(const Vec3& vector) {
  geometry_msgs::Vector3 msg;
  msg.x = vector.x();
  msg.y = vector.y();
  msg.z = vector.z();
  return msg;
}

geometry_msgs::Point PointToMsg(const Vec3& point) {
  geometry_msgs::Point msg;
  msg.x = point.x();
  msg.y = point.y();
  msg.z = point.z();
  return msg;
}

geometry_msgs::Pose PoseToMsg(const Pose& pose) {
  geometry_msgs::Pose msg;
  msg.position = PointToMsg(pose.translation);
  msg.orientation.w = pose.rotation.w();
  msg.orientation.x = pose.rotation.x();
  msg.orientation.y = pose.rotation.y();
  msg.orientation.z = pose.rotation.z();
  return msg;
}

sensor_msgs::LaserScan LaserScanToMsg(const io::LaserSensor& laser,
                                      const std::vector<double>& ranges, double scan_time) {
  sensor_msgs::LaserScan scan;
  scan.angle_min = static_cast<float>(laser.min_angle);
  scan.angle_max = static_cast<float>(laser.max_angle);
  scan.angle_increment = static_cast<float>(LaserAngleIncrement(laser));
  scan.time_increment = 0.0f;  // every ray of a scan is cast at one instant
  scan.scan_time = static_cast<float>(scan_time);
  scan.range_min = static_cast<float>(laser.range_min);
  scan.range_max = static_cast<float>(laser.range_max);
  scan.ranges.assign(ranges.begin(), ranges.end());
  scan.intensities.assign(ranges.size(), 0.0f);
  return scan;
}

sensor_msgs::PointCloud2 LaserCloudToMsg(const std::vector<Vec3>& directions_sensor,
                                         const std::vector<double>& ranges) {
  sensor_msgs::PointCloud2 cloud;
  sensor_msgs::PointField field;
  field.datatype = sensor_msgs::PointField::FLOAT32;
  field.count = 1;
  for (const char* name : {"x", "y", "z"}) {
    field.name = name;
    field.offset = static_cast<std::uint32_t>(4 * cloud.fields.size());
    cloud.fields.push_back(field);
  }
  cloud.point_step = 12;
  cloud.height = 1;
  cloud.is_dense = true;
  for (std::size_t i = 0; i < ranges.size() && i < directions_sensor.size(); ++i) {
    if (!std::isfinite(ranges[i])) continue;
    const Eigen::Vector3f point = (ranges[i] * directions_sensor[i]).cast<float>();
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(point.data());
    cloud.data.insert(cloud.data.end(), bytes, bytes + 12);
  }
  cloud.width = static_cast<std::uint32_t>(cloud.data.size() / cloud.point_step);
  cloud.row_step = cloud.width * cloud.point_step;
  return cloud;
}

sensor_msgs::Imu ImuToMsg(const ImuReading& reading) {
  sensor_msgs::Imu imu;
  const physics::Quat& q = reading.world_from_sensor;
  imu.orientation.x = q.x();
  imu.orientation.y = q.y();
  imu.orientation.z = q.z();
  imu.orientation.w = q.w();
  imu.angular_velocity = VectorToMsg(reading.angular_velocity_sensor);
  imu.linear_acceleration = VectorToMsg(reading.linear_acceleration_sensor);
  return imu;
}

nav_msgs::Odometry OdometryToMsg(const FrameState& state) {
  nav_msgs::Odometry odometry;
  odometry.pose.pose = PoseToMsg(state.world_from_frame);
  odometry.twist.twist = TwistToMsg(state.linear_velocity, state.angular_velocity);
  return odometry;
}

geometry_msgs::Twist TwistToMsg(const Vec3& linear_velocity, const Vec3& angular_velocity) {
  geometry_msgs::Twist msg;
  msg.linear = VectorToMsg(linear_velocity);
  msg.angular = VectorToMsg(angular_velocity);
  return msg;
}

geometry_msgs::TransformStamped TransformToMsg(const Pose& parent_from_child,
                                               const std::string& parent_frame,
                                               const std::string& child_frame,
                                               const ros::Time& stamp) {
  geometry_msgs::TransformStamped msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = parent_frame;
  msg.child_frame_id = child_frame;
  msg.transform.translation = VectorToMsg(parent_from_child.translation);
  msg.transform.rotation = PoseToMsg(parent_from_child).orientation;
  return msg;
}

ros::Time SimTimeToRos(double sim_time) {
  // ros::Time throws beyond its unsigned 32-bit seconds; a sim time outside
  // that range (or NaN) must not take the node down, so it is clamped.
  if (!(sim_time > 0.0)) return ros::Time(0);
  if (sim_time >= ros::TIME_MAX.toSec()) return ros::TIME_MAX;
  return ros::Time(sim_time);
}

rigid_body_sim::Contact ContactToMsg(const physics::ContactReport& contact,
                                     const std::string& body_a, const std::string& body_b) {
  rigid_body_sim::Contact msg;
  msg.body_a = body_a;
  msg.body_b = body_b;
  msg.position = PointToMsg(contact.position_world);
  msg.normal = VectorToMsg(contact.normal_world);
  msg.depth = contact.depth;
  msg.normal_velocity = contact.normal_velocity;
  msg.type = static_cast<std::uint8_t>(contact.type);
  msg.normal_impulse = contact.normal_impulse;
  msg.friction_impulse = VectorToMsg(contact.friction_impulse_world);
  msg.normal_force = contact.normal_force;
  return msg;
}

std::vector<visualization_msgs::Marker> ShapeMarkers(const std::vector<physics::ShapeDef>& shapes,
                                                     const std::string& ns,
                                                     const std::string& frame,
                                                     double half_space_size) {
  std::vector<visualization_msgs::Marker> markers;
  markers.reserve(shapes.size());
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const physics::ShapeDef& shape = shapes[i];
    visualization_msgs::Marker marker = BaseMarker(ns, static_cast<int>(i), frame);
    marker.frame_locked = true;
    marker.pose = PoseToMsg(shape.body_from_shape);
    marker.color = Color(0.6f, 0.65f, 0.7f, 0.9f);
    if (const auto* sphere = std::get_if<physics::Sphere>(&shape.geometry)) {
      marker.type = visualization_msgs::Marker::SPHERE;
      marker.scale.x = marker.scale.y = marker.scale.z = 2.0 * sphere->radius;
    } else if (const auto* cylinder = std::get_if<physics::Cylinder>(&shape.geometry)) {
      marker.type = visualization_msgs::Marker::CYLINDER;
      marker.scale.x = marker.scale.y = 2.0 * cylinder->radius;
      marker.scale.z = 2.0 * cylinder->half_length;
    } else if (const auto* hull =
                   std::get_if<std::shared_ptr<const physics::ConvexPolyhedron>>(&shape.geometry)) {
      marker.type = visualization_msgs::Marker::TRIANGLE_LIST;
      marker.scale.x = marker.scale.y = marker.scale.z = 1.0;
      const physics::TriangleMesh mesh = (*hull)->Triangulate();
      marker.points.reserve(3 * mesh.triangles.size());
      for (const Eigen::Vector3i& triangle : mesh.triangles) {
        for (int corner = 0; corner < 3; ++corner) {
          marker.points.push_back(PointToMsg(mesh.vertices[triangle[corner]]));
        }
      }
    } else if (const auto* mesh = std::get_if<physics::StaticMesh>(&shape.geometry)) {
      marker.type = visualization_msgs::Marker::TRIANGLE_LIST;
      marker.scale.x = marker.scale.y = marker.scale.z = 1.0;
      marker.points.reserve(3 * mesh->mesh->triangles().size());
      for (const physics::CollisionMesh::Triangle& triangle : mesh->mesh->triangles()) {
        for (const int vertex : triangle.vertices) {
          marker.points.push_back(PointToMsg(mesh->mesh->vertices()[vertex]));
        }
      }
    } else {
      // The half-space z <= 0 of the shape frame, drawn as a thin slab just
      // below its surface.
      constexpr double kSlabThickness = 0.01;  // m
      marker.type = visualization_msgs::Marker::CUBE;
      marker.scale.x = marker.scale.y = half_space_size;
      marker.scale.z = kSlabThickness;
      marker.pose = PoseToMsg(shape.body_from_shape *
                              Pose{Vec3(0.0, 0.0, -0.5 * kSlabThickness), Quat::Identity()});
      marker.color = Color(0.35f, 0.35f, 0.35f, 1.0f);
    }
    markers.push_back(std::move(marker));
  }
  return markers;
}

std::vector<visualization_msgs::Marker> DeleteMarkers(const std::string& ns, int count) {
  std::vector<visualization_msgs::Marker> markers;
  for (int id = 0; id < count; ++id) {
    visualization_msgs::Marker marker;
    marker.ns = ns;
    marker.id = id;
    marker.action = visualization_msgs::Marker::DELETE;
    markers.push_back(std::move(marker));
  }
  return markers;
}

visualization_msgs::MarkerArray ContactMarkers(const std::vector<physics::ContactReport>& contacts,
                                               int previous_count,
                                               const ContactMarkerStyle& style) {
  static const std::string kNamespace = "contacts";
  visualization_msgs::MarkerArray array;
  array.markers.reserve(2 * std::max<std::size_t>(contacts.size(), previous_count));
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const physics::ContactReport& contact = contacts[i];
    std_msgs::ColorRGBA color;
    switch (contact.type) {
      case physics::ContactType::kColliding:
        color = Color(0.9f, 0.1f, 0.1f, 1.0f);
        break;
      case physics::ContactType::kResting:
        color = Color(0.1f, 0.8f, 0.1f, 1.0f);
        break;
      case physics::ContactType::kSeparating:
        color = Color(0.2f, 0.3f, 0.9f, 1.0f);
        break;
    }
    visualization_msgs::Marker point = BaseMarker(kNamespace, static_cast<int>(2 * i), style.frame);
    point.header.stamp = style.stamp;
    point.type = visualization_msgs::Marker::SPHERE;
    point.pose.position = PointToMsg(contact.position_world);
    point.scale.x = point.scale.y = point.scale.z = style.point_size;
    point.color = color;
    array.markers.push_back(std::move(point));

    visualization_msgs::Marker arrow =
        BaseMarker(kNamespace, static_cast<int>(2 * i + 1), style.frame);
    arrow.header.stamp = style.stamp;
    arrow.type = visualization_msgs::Marker::ARROW;
    const double length =
        std::max(style.min_arrow, std::abs(contact.normal_force) * style.force_scale);
    arrow.points = {PointToMsg(contact.position_world),
                    PointToMsg(contact.position_world + length * contact.normal_world)};
    arrow.scale.x = 0.3 * style.point_size;  // shaft diameter
    arrow.scale.y = 0.6 * style.point_size;  // head diameter
    arrow.scale.z = 0.0;                     // default head length
    arrow.color = color;
    array.markers.push_back(std::move(arrow));
  }
  for (int id = static_cast<int>(2 * contacts.size()); id < 2 * previous_count; ++id) {
    visualization_msgs::Marker marker = BaseMarker(kNamespace, id, style.frame);
    marker.header.stamp = style.stamp;
    marker.action = visualization_msgs::Marker::DELETE;
    array.markers.push_back(std::move(marker));
  }
  return array;
}

LiveSettings LiveSettingsFromConfig(const rigid_body_sim::PhysicsConfig& config) {
  LiveSettings settings;
  settings.gravity = Vec3(config.gravity_x, config.gravity_y, config.gravity_z);
  settings.time_step = config.time_step;
  settings.real_time_factor = config.real_time_factor;
  settings.publish_rate = config.publish_rate;
  settings.defaults.friction = config.default_friction;
  settings.defaults.restitution = config.default_restitution;
  settings.velocity_iterations = config.solver_velocity_iterations;
  settings.position_iterations = config.solver_position_iterations;
  settings.solver_method = config.solver_method;
  settings.soft_substeps = config.solver_soft_step_substeps;
  settings.sleep_linear_velocity = config.sleep_linear_velocity;
  settings.sleep_angular_velocity = config.sleep_angular_velocity;
  return settings;
}

void LiveSettingsToConfig(const LiveSettings& settings, rigid_body_sim::PhysicsConfig* config) {
  config->gravity_x = settings.gravity.x();
  config->gravity_y = settings.gravity.y();
  config->gravity_z = settings.gravity.z();
  config->time_step = settings.time_step;
  config->real_time_factor = settings.real_time_factor;
  config->publish_rate = settings.publish_rate;
  config->default_friction = settings.defaults.friction;
  config->default_restitution = settings.defaults.restitution;
  config->solver_velocity_iterations = settings.velocity_iterations;
  config->solver_position_iterations = settings.position_iterations;
  config->solver_method = settings.solver_method;
  config->solver_soft_step_substeps = settings.soft_substeps;
  config->sleep_linear_velocity = settings.sleep_linear_velocity;
  config->sleep_angular_velocity = settings.sleep_angular_velocity;
}

}  // namespace rigid_body_sim::node
