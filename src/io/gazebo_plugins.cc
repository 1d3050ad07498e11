// The model plugins of <gazebo> elements (IMU, force-torque, ground-truth
// odometry, differential drive) and the walk over every <gazebo> element.
// Defaults follow gazebo_ros_pkgs (noetic-devel)
// gazebo_plugins/src/gazebo_ros_{imu,ft_sensor,p3d,diff_drive}.cpp and
// gazebo_ros_utils.h, unless a comment says why not.
#include "io/gazebo_plugins.h"

#include <algorithm>
#include <string>
#include <tuple>
#include <utility>

#include "io/urdf_elements.h"

namespace rigid_body_sim::io {
namespace {

using physics::Result;
using physics::Status;

constexpr char kWorld[] = "world";

// A required field the plugin refuses to load without.
Status Missing(const SdfScope& plugin, const std::string& path) {
  return Status::Error(plugin.Field(path) + " is required (the plugin loads nothing without it)");
}

// <bodyName>: required, a link of the model.
Result<std::string> ReadBody(const SdfScope& plugin, const GazeboModelNames& names) {
  const std::string body = plugin.String("bodyName", "");
  if (body.empty()) return Missing(plugin, "bodyName");
  if (names.links.count(body) == 0) {
    return Result<std::string>::Error(plugin.Field("bodyName") + " " + Quoted(body) +
                                      " is not a link of the model");
  }
  return body;
}

PluginCommon ModelPluginCommon(const SdfScope& plugin) {
  PluginCommon common;
  common.name = AttributeOf(*plugin.element(), "name");
  common.filename = AttributeOf(*plugin.element(), "filename");
  common.robot_namespace = plugin.String("robotNamespace", "");
  return common;
}

// libgazebo_ros_imu.so: the body's world orientation, angular velocity and
// (differenced) linear acceleration. <gaussianNoise> goes on the angular
// velocity and the acceleration only, as the plugin adds it; an <imu>
// block inside the plugin (TurtleBot3 writes one) is not read by it, so
// not here either.
Status ReadModelImu(const SdfScope& plugin, const GazeboModelNames& names, GazeboPlugins* plugins) {
  Result<std::string> body = ReadBody(plugin, names);
  if (!body.ok()) return body.status();
  ImuSensor imu;
  imu.common = ModelPluginCommon(plugin);
  imu.common.link = *body;
  imu.common.topic = plugin.String("topicName", "/default_imu");
  imu.common.frame_id = plugin.String("frameName", *body);
  Result<double> rate = plugin.Rate("updateRate", 0.0);
  if (!rate.ok()) return rate.status();
  imu.common.update_rate = *rate;
  Result<double> noise = plugin.Deviation("gaussianNoise");
  if (!noise.ok()) return noise.status();
  imu.angular_velocity.stddev = *noise;
  imu.linear_acceleration.stddev = *noise;
  // <xyzOffset> moves only the position, which an Imu message lacks.
  Result<physics::Quat> offset = plugin.Rotation("rpyOffset");
  if (!offset.ok()) return offset.status();
  imu.orientation_offset = *offset;
  plugins->imus.push_back(std::move(imu));
  return Status::Ok();
}

// libgazebo_ros_p3d.so. It reads <xyzOffset> and <rpyOffset> (older
// tutorials' <xyzOffsets>/<rpyOffsets> are not read by it); <topicName> and
// <bodyName> are required, <frameName> is "world" by default.
Status ReadGroundTruth(const SdfScope& plugin, const GazeboModelNames& names,
                       GazeboPlugins* plugins) {
  Result<std::string> body = ReadBody(plugin, names);
  if (!body.ok()) return body.status();
  GroundTruthOdometry odometry;
  odometry.common = ModelPluginCommon(plugin);
  odometry.common.link = *body;
  odometry.common.topic = plugin.String("topicName", "");
  if (odometry.common.topic.empty()) return Missing(plugin, "topicName");
  const std::string frame = plugin.String("frameName", kWorld);
  odometry.common.frame_id = frame;
  const bool world =
      frame.empty() || frame == kWorld || frame == "/world" || frame == "map" || frame == "/map";
  if (!world && names.links.count(frame) == 0) {
    return Status::Error(plugin.Field("frameName") + " " + Quoted(frame) +
                         " is neither world, map nor a link of the model");
  }
  if (!world) odometry.reference_link = frame;
  Result<double> rate = plugin.Rate("updateRate", 0.0);
  if (!rate.ok()) return rate.status();
  odometry.common.update_rate = *rate;
  Result<double> noise = plugin.Deviation("gaussianNoise");
  if (!noise.ok()) return noise.status();
  odometry.noise.stddev = *noise;
  Result<physics::Vec3> xyz =
      plugin.Vector("xyzOffset", Bounds(-kMaxShapeSize, kMaxShapeSize, "m"));
  if (!xyz.ok()) return xyz.status();
  Result<physics::Quat> rpy = plugin.Rotation("rpyOffset");
  if (!rpy.ok()) return rpy.status();
  odometry.offset = physics::Pose{*xyz, *rpy};
  plugins->odometry.push_back(std::move(odometry));
  return Status::Ok();
}

// <leftJoint> or <rightJoint>: a revolute or continuous joint of the
// model; the plugin's defaults are left_joint and right_joint.
Result<std::string> ReadWheelJoint(const SdfScope& plugin, const char* field,
                                   const std::string& fallback, const GazeboModelNames& names) {
  const std::string joint = plugin.String(field, fallback);
  const auto found = names.joints.find(joint);
  if (found == names.joints.end()) {
    return Result<std::string>::Error(plugin.Field(field) + " " + Quoted(joint) +
                                      " is not a joint of the model");
  }
  if (found->second.type != "revolute" && found->second.type != "continuous") {
    return Result<std::string>::Error(plugin.Field(field) + " " + Quoted(joint) + " is " +
                                      found->second.type +
                                      "; a wheel joint must be revolute or continuous");
  }
  return joint;
}

Status ReadWheels(const SdfScope& plugin, const GazeboModelNames& names, DiffDrive* drive) {
  Result<std::string> left = ReadWheelJoint(plugin, "leftJoint", "left_joint", names);
  if (!left.ok()) return left.status();
  Result<std::string> right = ReadWheelJoint(plugin, "rightJoint", "right_joint", names);
  if (!right.ok()) return right.status();
  drive->left_joint = *left;
  drive->right_joint = *right;
  const Bounds size = Bounds(0.0, kMaxShapeSize, "m").OpenLow();
  for (const auto& [field, value, bounds] :
       {std::tuple<const char*, double*, Bounds>{"wheelSeparation", &drive->wheel_separation, size},
        {"wheelDiameter", &drive->wheel_diameter, size},
        {"wheelTorque", &drive->wheel_torque, Bounds(0.0, kMaxSdfMagnitude, "N m").OpenLow()},
        {"wheelAcceleration", &drive->wheel_acceleration,
         Bounds(0.0, kMaxSdfMagnitude, "m/s^2")}}) {
    Result<double> number = plugin.Number(field, *value, bounds);
    if (!number.ok()) return number.status();
    *value = *number;
  }
  return Status::Ok();
}

// <odometrySource>: encoder or world (the plugin's default), or the
// numbers of its enum (0 encoder, 1 world), which descriptions write too
// (noetic's plugin reads those as world, with a warning).
Result<bool> ReadOdometryFromEncoders(const SdfScope& plugin) {
  const std::string source = plugin.String("odometrySource", "world");
  if (source == "encoder" || source == "0") return true;
  if (source == "world" || source == "1") return false;
  return Result<bool>::Error(plugin.Field("odometrySource") + " " + Quoted(source) +
                             " is not one of encoder, world, 0 or 1");
}

Status ReadDiffDriveFlags(const SdfScope& plugin, DiffDrive* drive) {
  bool publish_odom_tf = true;
  for (const auto& [field, value] :
       {std::pair<const char*, bool*>{"publishTf", &drive->publish_odometry},
        {"publishOdomTF", &publish_odom_tf},
        {"publishWheelTF", &drive->publish_wheel_tf},
        {"publishWheelJointState", &drive->publish_wheel_joint_state},
        {"legacyMode", &drive->legacy_mode}}) {
    Result<bool> flag = plugin.Boolean(field, *value);
    if (!flag.ok()) return flag.status();
    *value = *flag;
  }
  // The plugin sends the transform only while publishing odometry.
  drive->publish_tf = drive->publish_odometry && publish_odom_tf;
  Result<bool> encoders = ReadOdometryFromEncoders(plugin);
  if (!encoders.ok()) return encoders.status();
  drive->odometry_from_encoders = *encoders;
  return Status::Ok();
}

// libgazebo_ros_diff_drive.so, driving the model's root link.
Status ReadDiffDrive(const SdfScope& plugin, const GazeboModelNames& names,
                     GazeboPlugins* plugins) {
  DiffDrive drive;
  drive.common = ModelPluginCommon(plugin);
  drive.common.link = names.root_link;
  drive.common.topic = plugin.String("commandTopic", "cmd_vel");
  drive.odometry_topic = plugin.String("odometryTopic", drive.odometry_topic);
  drive.odometry_frame = plugin.String("odometryFrame", drive.odometry_frame);
  drive.robot_base_frame = plugin.String("robotBaseFrame", drive.robot_base_frame);
  drive.common.frame_id = drive.odometry_frame;
  Result<double> rate = plugin.Rate("updateRate", 100.0);
  if (!rate.ok()) return rate.status();
  drive.common.update_rate = *rate;
  if (Status status = ReadWheels(plugin, names, &drive); !status.ok()) return status;
  if (Status status = ReadDiffDriveFlags(plugin, &drive); !status.ok()) return status;
  plugins->diff_drives.push_back(std::move(drive));
  return Status::Ok();
}

// One <plugin> directly in a <gazebo> element: read when known, else
// listed as ignored.
Status ReadModelPlugin(const TiXmlElement& element, const GazeboModelNames& names,
                       GazeboPlugins* plugins) {
  const std::string name = AttributeOf(element, "name");
  const std::string filename = AttributeOf(element, "filename");
  const SdfScope plugin(&element, "<gazebo> plugin " + Quoted(name) + " (" + filename + ")");
  const std::string kind = PluginBaseName(filename);
  if (kind == "gazebo_ros_imu") return ReadModelImu(plugin, names, plugins);
  if (kind == "gazebo_ros_p3d") return ReadGroundTruth(plugin, names, plugins);
  if (kind == "gazebo_ros_diff_drive") return ReadDiffDrive(plugin, names, plugins);
  if (kind == "gazebo_ros_ft_sensor") {
    Result<ForceTorqueSensor> sensor =
        ReadForceTorque(plugin, plugin.String("jointName", ""), names, 0.0);
    if (!sensor.ok()) return sensor.status();
    plugins->force_torque.push_back(*sensor);
    return Status::Ok();
  }
  plugins->ignored.push_back(plugin.where());
  return Status::Ok();
}

}  // namespace

Result<ForceTorqueSensor> ReadForceTorque(const SdfScope& plugin, const std::string& joint,
                                          const GazeboModelNames& names, double default_rate) {
  if (joint.empty()) return Missing(plugin, "jointName");
  const auto found = names.joints.find(joint);
  if (found == names.joints.end()) {
    return Result<ForceTorqueSensor>::Error(plugin.where() + ": joint " + Quoted(joint) +
                                            " is not a joint of the model");
  }
  if (found->second.parent_link == kWorld) {
    return Result<ForceTorqueSensor>::Error(
        plugin.where() + ": joint " + Quoted(joint) +
        " is the joint to 'world'; a force-torque sensor reads a joint between links");
  }
  ForceTorqueSensor sensor;
  sensor.common = ModelPluginCommon(plugin);
  sensor.joint = joint;
  // The plugin reports in the child link's frame, under its name.
  sensor.common.link = found->second.child_link;
  sensor.common.frame_id = found->second.child_link;
  sensor.common.topic = plugin.String("topicName", "");
  if (sensor.common.topic.empty()) return Missing(plugin, "topicName");
  Result<double> rate = plugin.Rate("updateRate", default_rate);
  if (!rate.ok()) return rate.status();
  sensor.common.update_rate = *rate;
  Result<double> noise = plugin.Deviation("gaussianNoise");
  if (!noise.ok()) return noise.status();
  sensor.noise.stddev = *noise;
  return sensor;
}

GazeboModelNames ModelNamesOf(const LoadedModel& model, const TiXmlElement& robot) {
  GazeboModelNames names;
  names.root_link = model.root_link;
  for (const LinkFrame& link : model.links) {
    if (link.link_name != kWorld) names.links.insert(link.link_name);
  }
  for (const JointInfo& joint : model.joints) {
    names.joints[joint.name] = GazeboJoint{joint.type, joint.parent_link, joint.child_link};
  }
  // A static model's joint to 'world' is not among model.joints.
  for (const TiXmlElement* joint = robot.FirstChildElement("joint"); joint != nullptr;
       joint = joint->NextSiblingElement("joint")) {
    const TiXmlElement* parent = joint->FirstChildElement("parent");
    const TiXmlElement* child = joint->FirstChildElement("child");
    if (parent == nullptr || AttributeOf(*parent, "link") != kWorld) continue;
    names.joints.emplace(AttributeOf(*joint, "name"),
                         GazeboJoint{AttributeOf(*joint, "type"), kWorld,
                                     child == nullptr ? "" : AttributeOf(*child, "link")});
  }
  return names;
}

Result<GazeboPlugins> ReadGazeboPlugins(const TiXmlElement& robot, const GazeboModelNames& names) {
  GazeboPlugins plugins;
  for (const TiXmlElement* gazebo = robot.FirstChildElement("gazebo"); gazebo != nullptr;
       gazebo = gazebo->NextSiblingElement("gazebo")) {
    for (const TiXmlElement* plugin = gazebo->FirstChildElement("plugin"); plugin != nullptr;
         plugin = plugin->NextSiblingElement("plugin")) {
      if (Status status = ReadModelPlugin(*plugin, names, &plugins); !status.ok()) return status;
    }
    for (const TiXmlElement* sensor = gazebo->FirstChildElement("sensor"); sensor != nullptr;
         sensor = sensor->NextSiblingElement("sensor")) {
      if (Status status = ReadGazeboSensor(*gazebo, *sensor, names, &plugins); !status.ok()) {
        return status;
      }
    }
  }
  return plugins;
}

Status AddGazeboPlugins(const TiXmlElement& robot, LoadedModel* model) {
  Result<GazeboPlugins> plugins = ReadGazeboPlugins(robot, ModelNamesOf(*model, robot));
  if (!plugins.ok()) return plugins.status();
  model->plugins = std::move(plugins).value();
  for (const std::string& entry : model->plugins.ignored) {
    if (std::find(model->ignored.begin(), model->ignored.end(), entry) == model->ignored.end()) {
      model->ignored.push_back(entry);
    }
  }
  return Status::Ok();
}

}  // namespace rigid_body_sim::io
