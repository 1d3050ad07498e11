// Every parameter of the node, read once from the private namespace into one
// struct and validated. Units and defaults are listed here and in
// config/sim.yaml.
#ifndef RIGID_BODY_SIM_NODE_OPTIONS_H_
#define RIGID_BODY_SIM_NODE_OPTIONS_H_

#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "rigid_body_sim/io/mesh_process.h"
#include "rigid_body_sim/node/model_registry.h"
#include "rigid_body_sim/node/request_validation.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::node {

// The node's defaults of the world settings: the core's. One thread: on the
// two-core machines measured (docs/performance.md) the fork-join pool cost
// more than it saved, and the node's own threads want the second core.
inline physics::WorldSettings NodeWorldSettings() {
  physics::WorldSettings world;
  world.threads = 1;
  return world;
}

// ~solver/method's values, as physics::MotionSolverKind's.
inline constexpr const char* kExactSolver = "exact";
inline constexpr const char* kSoftStepSolver = "soft_step";

// The solver `name` names (kExactSolver or kSoftStepSolver), or false.
bool SolverMethodFromName(const std::string& name, physics::MotionSolverKind* kind);
std::string SolverMethodName(physics::MotionSolverKind kind);

struct NodeOptions {
  std::string world_frame = "world";  // ~world_frame: parent of every body frame
  // ~gravity [x, y, z] (m/s^2, default [0, 0, -9.81]), ~time_step (s, > 0,
  // default 1/240), ~contact_margin (m, 0.005), ~contact_reuse_distance (m,
  // 1e-3), ~continuous_fraction ((0, 1],
  // 0.25), ~max_turn_per_step (rad, (0, pi], pi/2), ~solver/{velocity_iterations (20),
  // velocity_tolerance (m/s, 1e-6), position_iterations (6), collision_velocity_threshold (m/s,
  // 0.01), contact_tolerance (m, 1e-5), penetration_slop (m, 1e-4), position_correction (1/step,
  // 0.2), max_collision_rounds (32), collision_iterations (30), max_pivoting_points (count, 32)}
  // and ~sleep/{enabled (true), linear_velocity (m/s, 0.05), angular_velocity (rad/s, 0.1),
  // time_to_sleep (s, 0.5), speeding_up_time (s, 0.2)}; see physics/world_settings.h. ~threads
  // (count, [0, 256], default 1; 0: one per core) is the threads a step runs on; any count gives
  // the same motion bit for bit.
  physics::WorldSettings world = NodeWorldSettings();
  // ~solver/method: "exact" (default) or "soft_step" (kSolverMethods),
  // which sets world.motion_solver; the soft step's own parameters are
  // ~solver/soft_step/{substeps (count, [1, 64], 4), contact_hertz (Hz, > 0,
  // 30), contact_damping_ratio (>= 0, 10), max_push_velocity (m/s, > 0, 3),
  // load_tracking ([0, 1], 0.05)}; see physics/world_settings.h.
  std::string solver_method = kExactSolver;
  double real_time_factor = 1.0;    // ~real_time_factor: sim time / real time, >= 0; 0 = flat out
  double publish_rate = 50.0;       // ~publish_rate: Hz of /tf, ~states, ~contacts, > 0
  bool paused = false;              // ~paused: start without stepping
  bool use_sim_time = false;        // /use_sim_time (global, default false): publish /clock
  bool ground_plane = true;         // ~ground_plane: static plane z = 0 named 'ground'
  double ground_friction = 0.8;     // ~ground_friction: Coulomb mu, >= 0
  double ground_restitution = 0.0;  // ~ground_restitution: in [0, 1]
  MaterialDefaults defaults;  // ~default_friction (0.5, >= 0), ~default_restitution (0.0, [0, 1])
  // ~default_density (kg/m^3, 1000), ~max_hull_vertices (count, 256) for
  // URDF loading.
  double default_density = 1000.0;
  int max_hull_vertices = 256;
  // ~balance_inertia (false): repair, with a warning, an <inertia> that is
  // not positive definite or misses I1 + I2 >= I3, instead of refusing it.
  bool balance_inertia = false;
  double status_period = 5.0;  // ~status_period: s of real time between INFO status lines, > 0
  // ~contact_force_scale: m of contact-marker arrow per N of normal force, > 0
  double contact_force_scale = 0.02;
  // ~max_position (m, 1e6), ~max_linear_speed (m/s, 1e4),
  // ~max_angular_speed (rad/s, 1e4), ~max_force (N, 1e9), ~max_torque (N m,
  // 1e9), ~max_wrench_duration (s, 3600), ~max_step_count (count, 100000),
  // ~max_trajectory_points (count, 100000, [1, 1e7]):
  // requests beyond them are refused (request_validation.h).
  RequestLimits limits;
  int max_links_per_model = 1000;  // ~max_links_per_model: count, >= 1
  // ~sensor_noise_seed: integer, [0, 2^31 - 1]; seeds the one generator of
  // every sensor's noise, so a run repeats its readings.
  int sensor_noise_seed = 0;
  // ~max_joints_per_model: count, [1, 999]: movable joints of one
  // articulated model (io::kDefaultMaxJointsPerModel, 999).
  int max_joints_per_model = io::kDefaultMaxJointsPerModel;
  // The position servo of joint commands (physics/articulation.h):
  // ~joint_stiffness (N m/rad or N/m, 1e5, (0, 1e12]) and ~joint_damping
  // (N m s/rad or N s/m, 1e3, [0, 1e12]).
  physics::ServoGains servo;
  int max_file_bytes = 256 << 20;  // ~max_file_bytes: URDF and mesh files, bytes, >= 1
  // Limits of the mesh helper process (io/mesh_process.h).
  int mesh_memory_limit = 1 << 30;  // ~mesh_memory_limit: bytes of address space, >= 2^24
  double mesh_cpu_limit = 30.0;     // ~mesh_cpu_limit: s of CPU, (0, 3600]
  // ~max_mesh_triangles: count, [1, 2^24]: triangles of one static mesh
  // (io::kDefaultMaxMeshTriangles, 4 Mi by default).
  int max_mesh_triangles = static_cast<int>(io::kDefaultMaxMeshTriangles);
  // ~models: spawned at start-up, in order; each entry has the fields of
  // Spawn (name, urdf, urdf_path, is_static, friction, restitution), pose:
  // [x, y, z, roll, pitch, yaw] (m, rad; default all 0) and twist:
  // [vx, vy, vz, wx, wy, wz] (m/s, rad/s; default all 0) and joints:
  // {name: position} (rad or m, as Spawn's joint fields).
  std::vector<ModelSpec> models;
};

// What ~set_physics and dynamic_reconfigure (cfg/Physics.cfg) may change while
// the node runs. The same ranges hold at start-up; the .cfg states them too.
struct LiveSettings {
  physics::Vec3 gravity = physics::Vec3(0.0, 0.0, -9.81);  // m/s^2, world frame
  double time_step = 1.0 / 240.0;                          // s
  double real_time_factor = 1.0;                           // 0 = as fast as possible
  double publish_rate = 50.0;                              // Hz
  MaterialDefaults defaults;
  int velocity_iterations = 20;  // solver sweeps
  int position_iterations = 6;
  std::string solver_method = kExactSolver;  // ~solver/method
  int soft_substeps = 4;                     // ~solver/soft_step/substeps
  double sleep_linear_velocity = 0.05;       // m/s
  double sleep_angular_velocity = 0.1;       // rad/s
};

// Ranges of the live settings; gravity, time step, real-time factor and
// friction share request_validation.h's.
inline constexpr double kCoarseTimeStep = kWarnTimeStep;  // s; longer steps log a warning
inline constexpr double kMinPublishRate = 0.1;            // Hz
inline constexpr double kMaxPublishRate = 1000.0;         // Hz
inline constexpr int kMaxIterations = 1000;
inline constexpr double kMaxSleepVelocity = 10.0;  // m/s and rad/s

LiveSettings LiveSettingsOf(const NodeOptions& options);

// Fails on the first value out of range, naming it (`prefix` + field), its
// value and the range.
physics::Status ValidateLiveSettings(const LiveSettings& settings, const std::string& prefix);

// Valid but doubtful values, each a message naming it: a time step above
// kCoarseTimeStep.
std::vector<std::string> LiveSettingsWarnings(const LiveSettings& settings,
                                              const std::string& prefix);

// The world settings with the live ones of `settings` put in.
physics::WorldSettings WithLiveSettings(physics::WorldSettings world, const LiveSettings& settings);

// Checks ranges and the model list (valid unique names, a URDF source each).
physics::Status ValidateNodeOptions(const NodeOptions& options);

// Reads every parameter from `private_node` (defaults for missing ones) and
// validates the result. Fails, naming the parameter, on a wrong type or an
// invalid value.
physics::Result<NodeOptions> ReadNodeOptions(const ros::NodeHandle& private_node);

// Writes every parameter's effective value (the default where it was unset)
// back under the private namespace, so that `rosparam get` shows what the
// node runs with. ~models is left as given.
void WriteNodeOptions(const NodeOptions& options, const ros::NodeHandle& private_node);

// Fixed-axis roll about x, then pitch about y, then yaw about z (URDF rpy,
// REP 103): R = Rz(yaw) Ry(pitch) Rx(roll).
physics::Quat QuatFromRollPitchYaw(double roll, double pitch, double yaw);

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_OPTIONS_H_
