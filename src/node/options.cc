#include "rigid_body_sim/node/options.h"

#include <cmath>
#include <set>
#include <sstream>

#include <xmlrpcpp/XmlRpcValue.h>

namespace rigid_body_sim::node {

using physics::FormatNumber;
using physics::Result;
using physics::Status;
using physics::Vec3;

namespace {

bool IsNumber(const XmlRpc::XmlRpcValue& value) {
  return value.getType() == XmlRpc::XmlRpcValue::TypeDouble ||
         value.getType() == XmlRpc::XmlRpcValue::TypeInt;
}

double ToDouble(XmlRpc::XmlRpcValue& value) {
  return value.getType() == XmlRpc::XmlRpcValue::TypeInt ? static_cast<int>(value)
                                                         : static_cast<double>(value);
}

// Typed readers for one XmlRpc value; `what` names it in errors.
Status ReadDouble(XmlRpc::XmlRpcValue& value, const std::string& what, double* out) {
  if (!IsNumber(value)) return Status::Error(what + " must be a number");
  *out = ToDouble(value);
  return Status::Ok();
}

Status ReadBool(XmlRpc::XmlRpcValue& value, const std::string& what, bool* out) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeBoolean) {
    return Status::Error(what + " must be true or false");
  }
  *out = static_cast<bool>(value);
  return Status::Ok();
}

Status ReadString(XmlRpc::XmlRpcValue& value, const std::string& what, std::string* out) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeString) {
    return Status::Error(what + " must be a string");
  }
  *out = static_cast<std::string>(value);
  return Status::Ok();
}

Status ReadInt(XmlRpc::XmlRpcValue& value, const std::string& what, int* out) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeInt) {
    return Status::Error(what + " must be an integer");
  }
  *out = static_cast<int>(value);
  return Status::Ok();
}

Status ReadDoubles(XmlRpc::XmlRpcValue& value, const std::string& what, int count,
                   std::vector<double>* out) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeArray || value.size() != count) {
    return Status::Error(what + " must be a list of " + std::to_string(count) + " numbers");
  }
  out->resize(count);
  for (int i = 0; i < count; ++i) {
    if (!IsNumber(value[i])) {
      return Status::Error(what + " must be a list of " + std::to_string(count) + " numbers");
    }
    (*out)[i] = ToDouble(value[i]);
  }
  return Status::Ok();
}

// Reads private parameter `name` with `reader` when it is set.
template <typename T, typename Reader>
Status ReadParam(const ros::NodeHandle& node, const std::string& name, Reader reader, T* out) {
  XmlRpc::XmlRpcValue value;
  if (!node.getParam(name, value)) return Status::Ok();
  const std::string shown = name.front() == '/' ? name : "~" + name;
  return reader(value, "parameter " + shown, out);
}

Status ReadModel(XmlRpc::XmlRpcValue& entry, int index, ModelSpec* spec) {
  const std::string what = "~models[" + std::to_string(index) + "]";
  if (entry.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    return Status::Error(what + " must be a dictionary");
  }
  static const std::set<std::string> kKeys = {"name",  "urdf",      "urdf_path", "pose",
                                              "twist", "is_static", "friction",  "restitution"};
  for (auto& [key, unused] : entry) {
    if (kKeys.count(key) == 0) return Status::Error(what + " has an unknown field '" + key + "'");
  }
  if (!entry.hasMember("name")) return Status::Error(what + " has no name");
  // Reads field `key` with `reader` when the entry has it.
  auto read_field = [&entry, &what](const char* key, auto reader, auto* out) {
    return entry.hasMember(key) ? reader(entry[key], what + "." + key, out) : Status::Ok();
  };
  for (const Status& status :
       {read_field("name", ReadString, &spec->name), read_field("urdf", ReadString, &spec->urdf),
        read_field("urdf_path", ReadString, &spec->urdf_path),
        read_field("is_static", ReadBool, &spec->is_static),
        read_field("friction", ReadDouble, &spec->friction),
        read_field("restitution", ReadDouble, &spec->restitution)}) {
    if (!status.ok()) return status;
  }
  std::vector<double> values;
  if (entry.hasMember("pose")) {
    if (Status status =
            ReadDoubles(entry["pose"], what + ".pose [x, y, z, roll, pitch, yaw]", 6, &values);
        !status.ok()) {
      return status;
    }
    spec->root_state.world_from_frame.translation = Vec3(values[0], values[1], values[2]);
    spec->root_state.world_from_frame.rotation =
        QuatFromRollPitchYaw(values[3], values[4], values[5]);
  }
  if (entry.hasMember("twist")) {
    if (Status status =
            ReadDoubles(entry["twist"], what + ".twist [vx, vy, vz, wx, wy, wz]", 6, &values);
        !status.ok()) {
      return status;
    }
    spec->root_state.linear_velocity = Vec3(values[0], values[1], values[2]);
    spec->root_state.angular_velocity = Vec3(values[3], values[4], values[5]);
  }
  return Status::Ok();
}

}  // namespace

physics::Quat QuatFromRollPitchYaw(double roll, double pitch, double yaw) {
  return physics::Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ()) *
                       Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
                       Eigen::AngleAxisd(roll, Vec3::UnitX()));
}

Status ValidateNodeOptions(const NodeOptions& options) {
  if (options.world_frame.empty()) return Status::Error("~world_frame is empty");
  if (options.world_frame.front() == '/') {
    return Status::Error("~world_frame '" + options.world_frame +
                         "' starts with '/'; tf2 frame ids have no leading slash");
  }
  if (!physics::IsFinite(options.world.gravity)) return Status::Error("~gravity is not finite");
  if (!(options.world.time_step > 0.0) || !std::isfinite(options.world.time_step)) {
    return Status::Error("~time_step " + FormatNumber(options.world.time_step) +
                         " s must be positive and finite");
  }
  if (Status status = physics::ValidateWorldSettings(options.world); !status.ok()) {
    return Status::Error(
        "world settings (~gravity, ~time_step, ~contact_margin, "
        "~continuous_fraction, ~solver, ~sleep): " +
        status.message());
  }
  if (!(options.real_time_factor >= 0.0) || !std::isfinite(options.real_time_factor)) {
    return Status::Error("~real_time_factor " + FormatNumber(options.real_time_factor) +
                         " must be >= 0 (0: as fast as possible)");
  }
  if (!(options.publish_rate > 0.0) || !std::isfinite(options.publish_rate)) {
    return Status::Error("~publish_rate " + FormatNumber(options.publish_rate) + " Hz must be positive");
  }
  const auto check_friction = [](double value, const std::string& name) {
    return value >= 0.0 && std::isfinite(value)
               ? Status::Ok()
               : Status::Error(name + " " + FormatNumber(value) + " must be >= 0");
  };
  const auto check_restitution = [](double value, const std::string& name) {
    return value >= 0.0 && value <= 1.0
               ? Status::Ok()
               : Status::Error(name + " " + FormatNumber(value) + " must be in [0, 1]");
  };
  for (const Status& status :
       {check_friction(options.ground_friction, "~ground_friction"),
        check_friction(options.defaults.friction, "~default_friction"),
        check_restitution(options.ground_restitution, "~ground_restitution"),
        check_restitution(options.defaults.restitution, "~default_restitution")}) {
    if (!status.ok()) return status;
  }
  if (!(options.default_density > 0.0) || !std::isfinite(options.default_density)) {
    return Status::Error("~default_density " + FormatNumber(options.default_density) +
                         " kg/m^3 must be positive");
  }
  if (options.max_hull_vertices < 4) {
    return Status::Error("~max_hull_vertices " + std::to_string(options.max_hull_vertices) +
                         " must be >= 4");
  }
  if (options.cylinder_segments < 3) {
    return Status::Error("~cylinder_segments " + std::to_string(options.cylinder_segments) +
                         " must be >= 3");
  }
  if (!(options.status_period > 0.0) || !std::isfinite(options.status_period)) {
    return Status::Error("~status_period " + FormatNumber(options.status_period) + " s must be positive");
  }
  if (!(options.contact_force_scale > 0.0) || !std::isfinite(options.contact_force_scale)) {
    return Status::Error("~contact_force_scale " + FormatNumber(options.contact_force_scale) +
                         " m/N must be positive");
  }
  std::set<std::string> model_names;
  for (const ModelSpec& spec : options.models) {
    if (Status status = ValidateModelName(spec.name); !status.ok()) {
      return Status::Error("~models: " + status.message());
    }
    if (!model_names.insert(spec.name).second) {
      return Status::Error("~models: the name '" + spec.name + "' is used twice");
    }
    if (spec.urdf.empty() && spec.urdf_path.empty()) {
      return Status::Error("~models: '" + spec.name + "' has neither urdf nor urdf_path");
    }
  }
  return Status::Ok();
}

Result<NodeOptions> ReadNodeOptions(const ros::NodeHandle& private_node) {
  NodeOptions options;
  std::vector<double> gravity;
  const std::vector<Status> reads = {
      ReadParam(private_node, "world_frame", ReadString, &options.world_frame),
      ReadParam(private_node, "time_step", ReadDouble, &options.world.time_step),
      ReadParam(private_node, "real_time_factor", ReadDouble, &options.real_time_factor),
      ReadParam(private_node, "publish_rate", ReadDouble, &options.publish_rate),
      ReadParam(private_node, "paused", ReadBool, &options.paused),
      ReadParam(
          private_node, "gravity",
          [](XmlRpc::XmlRpcValue& value, const std::string& what, std::vector<double>* out) {
            return ReadDoubles(value, what, 3, out);
          },
          &gravity),
      ReadParam(private_node, "ground_plane", ReadBool, &options.ground_plane),
      ReadParam(private_node, "ground_friction", ReadDouble, &options.ground_friction),
      ReadParam(private_node, "ground_restitution", ReadDouble, &options.ground_restitution),
      ReadParam(private_node, "default_friction", ReadDouble, &options.defaults.friction),
      ReadParam(private_node, "default_restitution", ReadDouble, &options.defaults.restitution),
      ReadParam(private_node, "default_density", ReadDouble, &options.default_density),
      ReadParam(private_node, "max_hull_vertices", ReadInt, &options.max_hull_vertices),
      ReadParam(private_node, "cylinder_segments", ReadInt, &options.cylinder_segments),
      ReadParam(private_node, "contact_margin", ReadDouble, &options.world.contact_margin),
      ReadParam(private_node, "contact_reuse_distance", ReadDouble,
                &options.world.contact_reuse_distance),
      ReadParam(private_node, "continuous_fraction", ReadDouble,
                &options.world.continuous_fraction),
      ReadParam(private_node, "solver/velocity_iterations", ReadInt,
                &options.world.solver.velocity_iterations),
      ReadParam(private_node, "solver/velocity_tolerance", ReadDouble,
                &options.world.solver.velocity_tolerance),
      ReadParam(private_node, "solver/position_iterations", ReadInt,
                &options.world.solver.position_iterations),
      ReadParam(private_node, "solver/collision_velocity_threshold", ReadDouble,
                &options.world.solver.collision_velocity_threshold),
      ReadParam(private_node, "solver/contact_tolerance", ReadDouble,
                &options.world.solver.contact_tolerance),
      ReadParam(private_node, "solver/penetration_slop", ReadDouble,
                &options.world.solver.penetration_slop),
      ReadParam(private_node, "solver/position_correction", ReadDouble,
                &options.world.solver.position_correction),
      ReadParam(private_node, "solver/max_collision_rounds", ReadInt,
                &options.world.solver.max_collision_rounds),
      ReadParam(private_node, "solver/collision_iterations", ReadInt,
                &options.world.solver.collision_iterations),
      ReadParam(private_node, "sleep/enabled", ReadBool, &options.world.sleep.enabled),
      ReadParam(private_node, "sleep/linear_velocity", ReadDouble,
                &options.world.sleep.linear_velocity),
      ReadParam(private_node, "sleep/angular_velocity", ReadDouble,
                &options.world.sleep.angular_velocity),
      ReadParam(private_node, "sleep/time_to_sleep", ReadDouble,
                &options.world.sleep.time_to_sleep),
      ReadParam(private_node, "sleep/speeding_up_time", ReadDouble,
                &options.world.sleep.speeding_up_time),
      ReadParam(private_node, "status_period", ReadDouble, &options.status_period),
      ReadParam(private_node, "contact_force_scale", ReadDouble, &options.contact_force_scale),
  };
  for (const Status& status : reads) {
    if (!status.ok()) return status;
  }
  ros::NodeHandle root_node;
  if (Status status = ReadParam(root_node, "/use_sim_time", ReadBool, &options.use_sim_time);
      !status.ok()) {
    return status;
  }
  if (!gravity.empty()) options.world.gravity = Vec3(gravity[0], gravity[1], gravity[2]);

  XmlRpc::XmlRpcValue models;
  if (private_node.getParam("models", models)) {
    if (models.getType() != XmlRpc::XmlRpcValue::TypeArray) {
      return Status::Error("parameter ~models must be a list");
    }
    for (int i = 0; i < models.size(); ++i) {
      ModelSpec spec;
      if (Status status = ReadModel(models[i], i, &spec); !status.ok()) return status;
      options.models.push_back(std::move(spec));
    }
  }
  if (Status status = ValidateNodeOptions(options); !status.ok()) return status;
  return options;
}

}  // namespace rigid_body_sim::node
