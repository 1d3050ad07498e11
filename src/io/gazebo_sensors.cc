// The <sensor>s of <gazebo reference="..."> elements and the ROS plugins
// inside them: lasers, IMUs, bumpers and force-torque sensors. Defaults
// follow gazebo_ros_pkgs (noetic-devel) gazebo_plugins/src/gazebo_ros_*.cpp
// and SDF's ray.sdf, unless a comment says why not.
#include <algorithm>
#include <string>
#include <utility>

#include "io/gazebo_plugins.h"
#include "io/gazebo_sdf.h"
#include "io/urdf_elements.h"

namespace rigid_body_sim::io {
namespace {

using physics::FormatNumber;
using physics::Result;
using physics::Status;

// A full turn either way, with room for the rounding descriptions write
// (TurtleBot3's 6.28319).
constexpr double kMaxScanAngle = 7.0;

// The sensor and the plugin being read, and the link or joint named by the
// <gazebo reference>.
struct SensorPlugin {
  SdfScope sensor;
  SdfScope plugin;
  std::string reference;
  std::string kind;  // the plugin's base name, e.g. gazebo_ros_laser
};

bool IsLaserPlugin(const std::string& kind) {
  return kind == "gazebo_ros_laser" || kind == "gazebo_ros_gpu_laser" ||
         kind == "gazebo_ros_block_laser";
}

// Whether this library reads plugin `kind` in a sensor of `type`. Gazebo
// refuses the CPU lasers in a gpu_ray and the reverse; the scan each
// describes is the same, so any laser plugin is read in either.
bool Reads(const std::string& type, const std::string& kind) {
  if (type == "ray" || type == "gpu_ray") return IsLaserPlugin(kind);
  if (type == "imu") return kind == "gazebo_ros_imu_sensor";
  if (type == "contact") return kind == "gazebo_ros_bumper";
  if (type == "force_torque") return kind == "gazebo_ros_ft_sensor";
  return false;
}

// What every sensor plugin has: names, link, pose, rate and namespace.
Result<PluginCommon> ReadCommon(const SensorPlugin& read) {
  PluginCommon common;
  common.name = AttributeOf(*read.sensor.element(), "name");
  if (common.name.empty()) common.name = AttributeOf(*read.plugin.element(), "name");
  common.filename = AttributeOf(*read.plugin.element(), "filename");
  common.link = read.reference;
  Result<physics::Pose> pose = read.sensor.PoseAt("pose");
  if (!pose.ok()) return pose.status();
  common.link_from_sensor = *pose;
  // SDF's sensor default: 0, every step.
  Result<double> rate = read.sensor.Rate("update_rate", 0.0);
  if (!rate.ok()) return rate.status();
  common.update_rate = *rate;
  common.robot_namespace = read.plugin.String("robotNamespace", "");
  common.frame_id = read.plugin.String("frameName", read.reference);
  return common;
}

struct ScanAxis {
  int samples = 1;
  double resolution = 1.0;
  double min_angle = 0.0;
  double max_angle = 0.0;
};

// <ray><scan><horizontal> or <vertical>; SDF's defaults, 640 horizontal
// samples, 1 vertical.
Result<ScanAxis> ReadScanAxis(const SdfScope& sensor, const std::string& name, int samples) {
  const std::string path = "ray/scan/" + name + "/";
  ScanAxis axis;
  Result<int> count = sensor.Count(path + "samples", samples, 1, kMaxLaserSamples);
  if (!count.ok()) return count.status();
  axis.samples = *count;
  Result<double> resolution =
      sensor.Number(path + "resolution", 1.0, Bounds(0.0, kMaxLaserSamples).OpenLow());
  if (!resolution.ok()) return resolution.status();
  axis.resolution = *resolution;
  Result<double> min_angle =
      sensor.Number(path + "min_angle", 0.0, Bounds(-kMaxScanAngle, kMaxScanAngle, "rad"));
  if (!min_angle.ok()) return min_angle.status();
  axis.min_angle = *min_angle;
  Result<double> max_angle = sensor.Number(
      path + "max_angle", 0.0, Bounds(*min_angle, kMaxScanAngle, "rad").LowNamed("min_angle"));
  if (!max_angle.ok()) return max_angle.status();
  axis.max_angle = *max_angle;
  return axis;
}

// <ray><range>: SDF's defaults are 0, so a laser must state its max.
Status ReadRange(const SdfScope& sensor, LaserSensor* laser) {
  Result<double> min = sensor.Number("ray/range/min", 0.0, Bounds(0.0, kMaxSdfMagnitude, "m"));
  if (!min.ok()) return min.status();
  Result<double> max = sensor.Number(
      "ray/range/max", 0.0, Bounds(*min, kMaxSdfMagnitude, "m").OpenLow().LowNamed("range_min"));
  if (!max.ok()) return max.status();
  Result<double> resolution =
      sensor.Number("ray/range/resolution", 0.0, Bounds(0.0, kMaxSdfMagnitude, "m"));
  if (!resolution.ok()) return resolution.status();
  laser->range_min = *min;
  laser->range_max = *max;
  laser->range_resolution = *resolution;
  return Status::Ok();
}

// The laser plugins read only <topicName>, <frameName> and
// <robotNamespace>; their <updateRate> or <update_rate> is not read (the
// block laser reads it and never uses it), so the sensor's sets the rate.
Status ReadLaser(const SensorPlugin& read, GazeboPlugins* plugins) {
  Result<PluginCommon> common = ReadCommon(read);
  if (!common.ok()) return common.status();
  LaserSensor laser;
  laser.common = *common;
  // The plugins' default topic is "/world", kept so that the node
  // publishes where Gazebo would; their default frame is "/world" too,
  // which would draw every scan at the origin, so the link's name it is.
  laser.common.topic = read.plugin.String("topicName", "/world");
  Result<ScanAxis> horizontal = ReadScanAxis(read.sensor, "horizontal", 640);
  if (!horizontal.ok()) return horizontal.status();
  Result<ScanAxis> vertical = ReadScanAxis(read.sensor, "vertical", 1);
  if (!vertical.ok()) return vertical.status();
  const double rays = static_cast<double>(horizontal->samples) * vertical->samples;
  if (rays > kMaxLaserSamples) {
    return Status::Error(read.sensor.Field("ray/scan") + " horizontal samples " +
                         std::to_string(horizontal->samples) + " times vertical samples " +
                         std::to_string(vertical->samples) + " (" + FormatNumber(rays) +
                         ") is outside the allowed range [1, " + std::to_string(kMaxLaserSamples) +
                         "]");
  }
  laser.horizontal_samples = horizontal->samples;
  laser.horizontal_resolution = horizontal->resolution;
  laser.min_angle = horizontal->min_angle;
  laser.max_angle = horizontal->max_angle;
  laser.vertical_samples = vertical->samples;
  laser.vertical_min_angle = vertical->min_angle;
  laser.vertical_max_angle = vertical->max_angle;
  if (Status status = ReadRange(read.sensor, &laser); !status.ok()) return status;
  Result<GaussianNoise> noise = read.sensor.Noise("ray/noise");
  if (!noise.ok()) return noise.status();
  laser.noise = *noise;
  const bool block = read.kind == "gazebo_ros_block_laser";
  if (block) {
    Result<double> extra = read.plugin.Deviation("gaussianNoise");
    if (!extra.ok()) return extra.status();
    laser.noise = WithExtraDeviation(laser.noise, *extra);
  }
  laser.point_cloud = block || laser.vertical_samples > 1;
  plugins->lasers.push_back(std::move(laser));
  return Status::Ok();
}

// The noise of one IMU reading in SDF 1.5 and later (<imu><NAME><x|y|z>
// <noise>): the axis with the largest stddev stands for all three.
Result<GaussianNoise> ReadAxesNoise(const SdfScope& sensor, const std::string& name) {
  GaussianNoise largest;
  for (const char* axis : {"x", "y", "z"}) {
    Result<GaussianNoise> noise = sensor.Noise("imu/" + name + "/" + axis + "/noise");
    if (!noise.ok()) return noise.status();
    if (noise->stddev >= largest.stddev && !noise->IsZero()) largest = *noise;
  }
  return largest;
}

// The sensor's own noise: SDF 1.5's per-axis blocks, else SDF 1.4's
// <imu><noise><type>gaussian</type><rate>/<accel>.
Status ReadImuSensorNoise(const SdfScope& sensor, ImuSensor* imu) {
  Result<GaussianNoise> rate = ReadAxesNoise(sensor, "angular_velocity");
  if (!rate.ok()) return rate.status();
  Result<GaussianNoise> accel = ReadAxesNoise(sensor, "linear_acceleration");
  if (!accel.ok()) return accel.status();
  imu->angular_velocity = *rate;
  imu->linear_acceleration = *accel;
  Result<bool> old_form = sensor.NoiseOn("imu/noise");
  if (!old_form.ok()) return old_form.status();
  if (!*old_form) return Status::Ok();
  if (sensor.Has("imu/noise/rate")) {
    Result<GaussianNoise> old_rate = sensor.NoiseValues("imu/noise/rate");
    if (!old_rate.ok()) return old_rate.status();
    imu->angular_velocity = *old_rate;
  }
  if (sensor.Has("imu/noise/accel")) {
    Result<GaussianNoise> old_accel = sensor.NoiseValues("imu/noise/accel");
    if (!old_accel.ok()) return old_accel.status();
    imu->linear_acceleration = *old_accel;
  }
  return Status::Ok();
}

// libgazebo_ros_imu_sensor.so. It publishes at the sensor's updates,
// throttled to <updateRateHZ> (default 1 Hz), so the slower of the two
// positive rates; it adds N(0, <gaussianNoise>^2) to every reading on top
// of the sensor's noise, and to each of the orientation quaternion's
// components (about twice that in rad of a small rotation). It refuses to
// load without <frameName>; here the link's name stands in.
Status ReadImuSensor(const SensorPlugin& read, GazeboPlugins* plugins) {
  Result<PluginCommon> common = ReadCommon(read);
  if (!common.ok()) return common.status();
  ImuSensor imu;
  imu.common = *common;
  imu.common.topic = read.plugin.String("topicName", "imu_data");
  Result<double> plugin_rate = read.plugin.Rate("updateRateHZ", 1.0);
  if (!plugin_rate.ok()) return plugin_rate.status();
  const double sensor_rate = imu.common.update_rate;
  imu.common.update_rate = sensor_rate > 0.0 && *plugin_rate > 0.0
                               ? std::min(sensor_rate, *plugin_rate)
                               : std::max(sensor_rate, *plugin_rate);
  if (Status status = ReadImuSensorNoise(read.sensor, &imu); !status.ok()) return status;
  Result<double> extra = read.plugin.Deviation("gaussianNoise");
  if (!extra.ok()) return extra.status();
  imu.orientation = WithExtraDeviation(imu.orientation, 2.0 * *extra);
  imu.angular_velocity = WithExtraDeviation(imu.angular_velocity, *extra);
  imu.linear_acceleration = WithExtraDeviation(imu.linear_acceleration, *extra);
  // Only the rotation of the offset acts; the plugin reads <xyzOffset>
  // and never uses it.
  Result<physics::Quat> offset = read.plugin.Rotation("rpyOffset");
  if (!offset.ok()) return offset.status();
  imu.orientation_offset = *offset;
  plugins->imus.push_back(std::move(imu));
  return Status::Ok();
}

// libgazebo_ros_bumper.so: topic "bumper_states" and frame "world" by
// default, as the plugin's (contacts in the world frame are of use).
Status ReadBumper(const SensorPlugin& read, GazeboPlugins* plugins) {
  Result<PluginCommon> common = ReadCommon(read);
  if (!common.ok()) return common.status();
  BumperSensor bumper;
  bumper.common = *common;
  bumper.common.topic = read.plugin.String("bumperTopicName", "bumper_states");
  bumper.common.frame_id = read.plugin.String("frameName", "world");
  plugins->bumpers.push_back(std::move(bumper));
  return Status::Ok();
}

Status ReadSensorPlugin(const SensorPlugin& read, const GazeboModelNames& names,
                        GazeboPlugins* plugins) {
  if (read.kind == "gazebo_ros_ft_sensor") {
    Result<double> sensor_rate = read.sensor.Rate("update_rate", 0.0);
    if (!sensor_rate.ok()) return sensor_rate.status();
    Result<ForceTorqueSensor> sensor =
        ReadForceTorque(read.plugin, read.reference, names, *sensor_rate);
    if (!sensor.ok()) return sensor.status();
    ForceTorqueSensor force_torque = *sensor;
    const std::string name = AttributeOf(*read.sensor.element(), "name");
    if (!name.empty()) force_torque.common.name = name;
    plugins->force_torque.push_back(std::move(force_torque));
    return Status::Ok();
  }
  if (names.links.count(read.reference) == 0) {
    return Status::Error(read.sensor.where() + ": " + Quoted(read.reference) +
                         " is not a link of the model");
  }
  if (IsLaserPlugin(read.kind)) return ReadLaser(read, plugins);
  if (read.kind == "gazebo_ros_imu_sensor") return ReadImuSensor(read, plugins);
  return ReadBumper(read, plugins);
}

}  // namespace

Status ReadGazeboSensor(const TiXmlElement& gazebo, const TiXmlElement& sensor,
                        const GazeboModelNames& names, GazeboPlugins* plugins) {
  const std::string reference = AttributeOf(gazebo, "reference");
  const std::string type = AttributeOf(sensor, "type");
  const std::string name = AttributeOf(sensor, "name");
  const std::string where = "<gazebo reference=" + Quoted(reference) + "> sensor " + Quoted(name);
  bool read_any = false;
  for (const TiXmlElement* plugin = sensor.FirstChildElement("plugin"); plugin != nullptr;
       plugin = plugin->NextSiblingElement("plugin")) {
    const std::string kind = PluginBaseName(AttributeOf(*plugin, "filename"));
    if (!Reads(type, kind)) continue;
    const SensorPlugin read{
        SdfScope(&sensor, where),
        SdfScope(plugin, where + " plugin " + Quoted(AttributeOf(*plugin, "name"))), reference,
        kind};
    if (Status status = ReadSensorPlugin(read, names, plugins); !status.ok()) return status;
    read_any = true;
  }
  // Without a plugin Gazebo's sensor publishes nothing to ROS.
  if (!read_any) plugins->ignored.push_back(where + " (" + type + ")");
  return Status::Ok();
}

}  // namespace rigid_body_sim::io
