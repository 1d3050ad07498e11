#include "rigid_body_sim/node/options.h"

#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <type_traits>
#include <variant>

#include <ros/console.h>
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

// `joints: {elbow: 0.5, ...}`: initial positions of movable joints, rad or m.
Status ReadJoints(XmlRpc::XmlRpcValue& value, const std::string& what,
                  std::map<std::string, double>* out) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    return Status::Error(what + " must be a dictionary {joint: position}");
  }
  for (auto& [name, position] : value) {
    if (!IsNumber(position)) return Status::Error(what + "." + name + " must be a number");
    (*out)[name] = ToDouble(position);
  }
  return Status::Ok();
}

Status ReadModel(XmlRpc::XmlRpcValue& entry, int index, ModelSpec* spec) {
  const std::string what = "~models[" + std::to_string(index) + "]";
  if (entry.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    return Status::Error(what + " must be a dictionary");
  }
  static const std::set<std::string> kKeys = {
      "name",        "urdf",   "urdf_path",       "pose",      "twist",   "is_static", "friction",
      "restitution", "joints", "robot_namespace", "tf_prefix", "tf_mode", "hold"};
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
        read_field("restitution", ReadDouble, &spec->restitution),
        read_field("joints", ReadJoints, &spec->joint_positions),
        read_field("robot_namespace", ReadString, &spec->robot_namespace),
        read_field("tf_prefix", ReadString, &spec->tf_prefix),
        read_field("hold", ReadBool, &spec->hold)}) {
    if (!status.ok()) return status;
  }
  if (entry.hasMember("tf_mode")) {
    std::string mode;
    if (Status status = ReadString(entry["tf_mode"], what + ".tf_mode", &mode); !status.ok()) {
      return status;
    }
    Result<TfMode> tf_mode = TfModeFromName(mode);
    if (!tf_mode.ok()) return Status::Error(what + ": " + tf_mode.message());
    spec->tf_mode = *tf_mode;
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

bool SolverMethodFromName(const std::string& name, physics::MotionSolverKind* kind) {
  if (name == kExactSolver) {
    *kind = physics::MotionSolverKind::kExact;
  } else if (name == kSoftStepSolver) {
    *kind = physics::MotionSolverKind::kSoftStep;
  } else {
    return false;
  }
  return true;
}

std::string SolverMethodName(physics::MotionSolverKind kind) {
  return kind == physics::MotionSolverKind::kSoftStep ? kSoftStepSolver : kExactSolver;
}

LiveSettings LiveSettingsOf(const NodeOptions& options) {
  LiveSettings live;
  live.gravity = options.world.gravity;
  live.time_step = options.world.time_step;
  live.real_time_factor = options.real_time_factor;
  live.publish_rate = options.publish_rate;
  live.defaults = options.defaults;
  live.velocity_iterations = options.world.solver.velocity_iterations;
  live.position_iterations = options.world.solver.position_iterations;
  live.solver_method = options.solver_method;
  live.soft_substeps = options.world.soft_step.substeps;
  live.sleep_linear_velocity = options.world.sleep.linear_velocity;
  live.sleep_angular_velocity = options.world.sleep.angular_velocity;
  return live;
}

physics::WorldSettings WithLiveSettings(physics::WorldSettings world,
                                        const LiveSettings& settings) {
  world.gravity = settings.gravity;
  world.time_step = settings.time_step;
  world.solver.velocity_iterations = settings.velocity_iterations;
  world.solver.position_iterations = settings.position_iterations;
  // Validated names only reach here (ValidateLiveSettings).
  SolverMethodFromName(settings.solver_method, &world.motion_solver);
  world.soft_step.substeps = settings.soft_substeps;
  world.sleep.linear_velocity = settings.sleep_linear_velocity;
  world.sleep.angular_velocity = settings.sleep_angular_velocity;
  return world;
}

namespace {

// `value` in [low, high], else an error naming it with its unit and range.
Status CheckRange(const std::string& name, double value, double low, double high,
                  const std::string& unit) {
  if (value >= low && value <= high) return Status::Ok();  // false for NaN
  const std::string shown_unit = unit.empty() ? "" : " " + unit;
  return Status::Error(name + " " + FormatNumber(value) + shown_unit + " is outside [" +
                       FormatNumber(low) + ", " + FormatNumber(high) + "]" + shown_unit);
}

Status CheckSolverMethod(const std::string& name, const std::string& method) {
  physics::MotionSolverKind kind;
  if (SolverMethodFromName(method, &kind)) return Status::Ok();
  return Status::Error(name + " '" + method + "' is not a solver: '" + kExactSolver + "' or '" +
                       kSoftStepSolver + "'");
}

}  // namespace

Status ValidateLiveSettings(const LiveSettings& settings, const std::string& prefix) {
  const char* axes[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    if (Status status = CheckRange(prefix + "gravity." + axes[i], settings.gravity[i], -kMaxGravity,
                                   kMaxGravity, "m/s^2");
        !status.ok()) {
      return status;
    }
  }
  for (const Status& status : {
           CheckRange(prefix + "time_step", settings.time_step, kMinTimeStep, kMaxTimeStep, "s"),
           ValidateRealTimeFactor(settings.real_time_factor, prefix + "real_time_factor"),
           CheckRange(prefix + "publish_rate", settings.publish_rate, kMinPublishRate,
                      kMaxPublishRate, "Hz"),
           CheckRange(prefix + "default_friction", settings.defaults.friction, 0.0, kMaxFriction,
                      ""),
           CheckRange(prefix + "default_restitution", settings.defaults.restitution, 0.0, 1.0, ""),
           CheckRange(prefix + "solver/velocity_iterations", settings.velocity_iterations, 1,
                      kMaxIterations, ""),
           CheckRange(prefix + "solver/position_iterations", settings.position_iterations, 0,
                      kMaxIterations, ""),
           CheckSolverMethod(prefix + "solver/method", settings.solver_method),
           CheckRange(prefix + "solver/soft_step/substeps", settings.soft_substeps, 1,
                      physics::kMaxSoftSubsteps, ""),
           CheckRange(prefix + "sleep/linear_velocity", settings.sleep_linear_velocity, 0.0,
                      kMaxSleepVelocity, "m/s"),
           CheckRange(prefix + "sleep/angular_velocity", settings.sleep_angular_velocity, 0.0,
                      kMaxSleepVelocity, "rad/s"),
       }) {
    if (!status.ok()) return status;
  }
  return Status::Ok();
}

std::vector<std::string> LiveSettingsWarnings(const LiveSettings& settings,
                                              const std::string& prefix) {
  std::vector<std::string> warnings;
  if (settings.time_step > kCoarseTimeStep) {
    warnings.push_back(prefix + "time_step " + FormatNumber(settings.time_step) +
                       " s is above 1/30 s: contacts and fast bodies are resolved coarsely" +
                       (settings.time_step == kMaxTimeStep
                            ? " (it is the maximum; dynamic_reconfigure clamps larger values to it)"
                            : ""));
  }
  return warnings;
}

namespace {

// One scalar parameter's allowed range, with its unit; an open end
// excludes its bound.
struct ParamRange {
  const char* name;
  double value;
  double low;
  double high;
  const char* unit;
  bool low_open = false;
  bool high_open = false;
};

Status CheckParamRange(const ParamRange& range) {
  const bool above_low = range.low_open ? range.value > range.low : range.value >= range.low;
  const bool below_high = range.high_open ? range.value < range.high : range.value <= range.high;
  if (above_low && below_high) return Status::Ok();  // false for NaN
  const std::string unit = *range.unit == '\0' ? "" : std::string(" ") + range.unit;
  return Status::Error(std::string(range.name) + " " + FormatNumber(range.value) + unit +
                       " is outside the allowed range " + (range.low_open ? "(" : "[") +
                       FormatNumber(range.low) + ", " + FormatNumber(range.high) +
                       (range.high_open ? ")" : "]") + unit);
}

// The node's own scalar parameters and their ranges, in the order they are
// checked; the world's settings are checked by physics::ValidateWorldSettings,
// the live ones by ValidateLiveSettings.
std::vector<ParamRange> NodeParamRanges(const NodeOptions& options) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  // The servo is implicit, so any gain is stable; the bound keeps dt k
  // (and so the soft row's terms) far from overflow.
  constexpr double kMaxServoGain = 1e12;
  auto count = [](auto value) { return static_cast<double>(value); };
  return {
      {"~max_links_per_model", count(options.max_links_per_model), 1, 1e9, ""},
      {"~sensor_noise_seed", count(options.sensor_noise_seed), 0, 2147483647.0, ""},
      // The articulation holds at most 1000 links (articulation_system.cc).
      {"~max_joints_per_model", count(options.max_joints_per_model), 1, 999, ""},
      {"~max_mesh_triangles", count(options.max_mesh_triangles), 1,
       count(physics::CollisionMesh::kMaxTriangles), ""},
      {"~max_file_bytes", count(options.max_file_bytes), 1, 2147483647.0, "bytes"},
      {"~mesh_memory_limit", count(options.mesh_memory_limit), 16777216.0, 2147483647.0, "bytes"},
      {"~joint_stiffness", options.servo.stiffness, 0, kMaxServoGain, "N m/rad", true},
      {"~joint_damping", options.servo.damping, 0, kMaxServoGain, "N m s/rad"},
      {"~mesh_cpu_limit", options.mesh_cpu_limit, 0, 3600, "s", true},
      {"~threads", count(options.world.threads), 0, count(physics::kMaxThreads), ""},
      {"~ground_friction", options.ground_friction, 0, kInfinity, "", false, true},
      {"~ground_restitution", options.ground_restitution, 0, 1, ""},
      {"~default_density", options.default_density, 0, kInfinity, "kg/m^3", true, true},
      {"~max_hull_vertices", count(options.max_hull_vertices), 4, kInfinity, "", false, true},
      {"~status_period", options.status_period, 0, kInfinity, "s", true, true},
      {"~contact_force_scale", options.contact_force_scale, 0, kInfinity, "m/N", true, true},
  };
}

}  // namespace

Status ValidateNodeOptions(const NodeOptions& options) {
  if (options.world_frame.empty()) return Status::Error("~world_frame is empty");
  if (options.world_frame.front() == '/') {
    return Status::Error("~world_frame '" + options.world_frame +
                         "' starts with '/'; tf2 frame ids have no leading slash");
  }
  for (const Status& status :
       {ValidateGravity(options.world.gravity, "~gravity"),
        ValidateTimeStep(options.world.time_step, "~time_step"),
        ValidateRealTimeFactor(options.real_time_factor, "~real_time_factor"),
        ValidateRequestLimits(options.limits)}) {
    if (!status.ok()) return status;
  }
  for (const ParamRange& range : NodeParamRanges(options)) {
    if (Status status = CheckParamRange(range); !status.ok()) return status;
  }
  if (Status status = physics::ValidateWorldSettings(options.world); !status.ok()) {
    return Status::Error(
        "world settings (~gravity, ~time_step, ~contact_margin, "
        "~continuous_fraction, ~solver, ~solver/soft_step, ~sleep): " +
        status.message());
  }
  if (Status status = ValidateLiveSettings(LiveSettingsOf(options), "~"); !status.ok()) {
    return status;
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
    if (Status status = ValidateModelSpec(spec, options.limits); !status.ok()) {
      return Status::Error("~models: '" + spec.name + "': " + status.message());
    }
  }
  return Status::Ok();
}

namespace {

// One scalar parameter of the private namespace and the option it sets.
struct ScalarParam {
  const char* name;
  std::variant<double*, int*, bool*, std::string*> value;
};

// Every scalar parameter, named as under ~; the 3-vector ~gravity and the
// list ~models are read on their own.
std::vector<ScalarParam> ScalarParams(NodeOptions* options) {
  physics::WorldSettings& world = options->world;
  physics::SolverSettings& solver = world.solver;
  physics::SleepSettings& sleep = world.sleep;
  return {
      {"world_frame", &options->world_frame},
      {"time_step", &world.time_step},
      {"real_time_factor", &options->real_time_factor},
      {"publish_rate", &options->publish_rate},
      {"paused", &options->paused},
      {"ground_plane", &options->ground_plane},
      {"ground_friction", &options->ground_friction},
      {"ground_restitution", &options->ground_restitution},
      {"default_friction", &options->defaults.friction},
      {"default_restitution", &options->defaults.restitution},
      {"default_density", &options->default_density},
      {"balance_inertia", &options->balance_inertia},
      {"max_hull_vertices", &options->max_hull_vertices},
      {"contact_margin", &world.contact_margin},
      {"contact_reuse_distance", &world.contact_reuse_distance},
      {"threads", &world.threads},
      {"continuous_fraction", &world.continuous_fraction},
      {"max_turn_per_step", &world.max_turn_per_step},
      {"solver/velocity_iterations", &solver.velocity_iterations},
      {"solver/velocity_tolerance", &solver.velocity_tolerance},
      {"solver/position_iterations", &solver.position_iterations},
      {"solver/collision_velocity_threshold", &solver.collision_velocity_threshold},
      {"solver/contact_tolerance", &solver.contact_tolerance},
      {"solver/penetration_slop", &solver.penetration_slop},
      {"solver/position_correction", &solver.position_correction},
      {"solver/max_collision_rounds", &solver.max_collision_rounds},
      {"solver/collision_iterations", &solver.collision_iterations},
      {"solver/max_pivoting_points", &solver.max_pivoting_points},
      {"solver/method", &options->solver_method},
      {"solver/soft_step/substeps", &world.soft_step.substeps},
      {"solver/soft_step/contact_hertz", &world.soft_step.contact_hertz},
      {"solver/soft_step/contact_damping_ratio", &world.soft_step.contact_damping_ratio},
      {"solver/soft_step/max_push_velocity", &world.soft_step.max_push_velocity},
      {"solver/soft_step/load_tracking", &world.soft_step.load_tracking},
      {"sleep/enabled", &sleep.enabled},
      {"sleep/linear_velocity", &sleep.linear_velocity},
      {"sleep/angular_velocity", &sleep.angular_velocity},
      {"sleep/time_to_sleep", &sleep.time_to_sleep},
      {"sleep/speeding_up_time", &sleep.speeding_up_time},
      {"status_period", &options->status_period},
      {"contact_force_scale", &options->contact_force_scale},
      {"max_position", &options->limits.max_position},
      {"max_linear_speed", &options->limits.max_linear_speed},
      {"max_angular_speed", &options->limits.max_angular_speed},
      {"max_force", &options->limits.max_force},
      {"max_torque", &options->limits.max_torque},
      {"max_wrench_duration", &options->limits.max_wrench_duration},
      {"max_step_count", &options->limits.max_step_count},
      {"max_trajectory_points", &options->limits.max_trajectory_points},
      {"max_links_per_model", &options->max_links_per_model},
      {"sensor_noise_seed", &options->sensor_noise_seed},
      {"max_joints_per_model", &options->max_joints_per_model},
      {"joint_stiffness", &options->servo.stiffness},
      {"joint_damping", &options->servo.damping},
      {"max_file_bytes", &options->max_file_bytes},
      {"mesh_memory_limit", &options->mesh_memory_limit},
      {"mesh_cpu_limit", &options->mesh_cpu_limit},
      {"max_mesh_triangles", &options->max_mesh_triangles},
  };
}

Status ReadScalar(const ros::NodeHandle& node, const ScalarParam& param) {
  return std::visit(
      [&](auto* out) {
        using T = std::remove_pointer_t<decltype(out)>;
        if constexpr (std::is_same_v<T, double>) {
          return ReadParam(node, param.name, ReadDouble, out);
        } else if constexpr (std::is_same_v<T, int>) {
          return ReadParam(node, param.name, ReadInt, out);
        } else if constexpr (std::is_same_v<T, bool>) {
          return ReadParam(node, param.name, ReadBool, out);
        } else {
          static_assert(std::is_same_v<T, std::string>);
          return ReadParam(node, param.name, ReadString, out);
        }
      },
      param.value);
}

Status ReadModels(const ros::NodeHandle& private_node, std::vector<ModelSpec>* models) {
  XmlRpc::XmlRpcValue list;
  if (!private_node.getParam("models", list)) return Status::Ok();
  if (list.getType() != XmlRpc::XmlRpcValue::TypeArray) {
    return Status::Error("parameter ~models must be a list");
  }
  for (int i = 0; i < list.size(); ++i) {
    ModelSpec spec;
    if (Status status = ReadModel(list[i], i, &spec); !status.ok()) return status;
    models->push_back(std::move(spec));
  }
  return Status::Ok();
}

}  // namespace

Result<NodeOptions> ReadNodeOptions(const ros::NodeHandle& private_node) {
  NodeOptions options;
  for (const ScalarParam& param : ScalarParams(&options)) {
    if (Status status = ReadScalar(private_node, param); !status.ok()) return status;
  }
  std::vector<double> gravity;
  if (Status status = ReadParam(
          private_node, "gravity",
          [](XmlRpc::XmlRpcValue& value, const std::string& what, std::vector<double>* out) {
            return ReadDoubles(value, what, 3, out);
          },
          &gravity);
      !status.ok()) {
    return status;
  }
  if (!gravity.empty()) options.world.gravity = Vec3(gravity[0], gravity[1], gravity[2]);
  ros::NodeHandle root_node;
  if (Status status = ReadParam(root_node, "/use_sim_time", ReadBool, &options.use_sim_time);
      !status.ok()) {
    return status;
  }
  if (Status status = ReadModels(private_node, &options.models); !status.ok()) return status;
  if (Status status = ValidateNodeOptions(options); !status.ok()) return status;
  SolverMethodFromName(options.solver_method, &options.world.motion_solver);
  if (options.world.time_step > kWarnTimeStep) {
    ROS_WARN("~time_step %g s is above %g s: contacts and fast bodies will be coarse",
             options.world.time_step, kWarnTimeStep);
  }
  return options;
}

void WriteNodeOptions(const NodeOptions& options, const ros::NodeHandle& private_node) {
  NodeOptions copy = options;
  for (const ScalarParam& param : ScalarParams(&copy)) {
    std::visit([&](auto* value) { private_node.setParam(param.name, *value); }, param.value);
  }
  const Vec3& gravity = options.world.gravity;
  private_node.setParam("gravity", std::vector<double>{gravity.x(), gravity.y(), gravity.z()});
}

}  // namespace rigid_body_sim::node
