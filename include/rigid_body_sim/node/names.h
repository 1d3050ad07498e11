// Every topic, service and reserved name of the node. Names without a
// leading slash live in the node's private namespace (~).
#ifndef RIGID_BODY_SIM_NODE_NAMES_H_
#define RIGID_BODY_SIM_NODE_NAMES_H_

namespace rigid_body_sim::node::names {

inline constexpr char kDefaultNodeName[] = "rigid_body_sim";

// Services (~).
inline constexpr char kSpawnService[] = "spawn";
inline constexpr char kDeleteService[] = "delete";
inline constexpr char kResetService[] = "reset";
inline constexpr char kSetPausedService[] = "set_paused";
inline constexpr char kStepService[] = "step";
inline constexpr char kGetStateService[] = "get_state";
inline constexpr char kRayCastService[] = "ray_cast";
inline constexpr char kSetStateService[] = "set_state";
inline constexpr char kApplyWrenchService[] = "apply_wrench";
inline constexpr char kGetPhysicsService[] = "get_physics";
inline constexpr char kSetPhysicsService[] = "set_physics";
inline constexpr char kCancelStepService[] = "cancel_step";
inline constexpr char kGetWorldPropertiesService[] = "get_world_properties";
inline constexpr char kGetModelPropertiesService[] = "get_model_properties";
inline constexpr char kResetWorldService[] = "reset_world";
inline constexpr char kResetSimulationService[] = "reset_simulation";
inline constexpr char kSetJointStateService[] = "set_joint_state";

// Topics (~).
inline constexpr char kContactsTopic[] = "contacts";
inline constexpr char kStatesTopic[] = "states";
inline constexpr char kContactMarkersTopic[] = "contact_markers";
inline constexpr char kBodyMarkersTopic[] = "body_markers";
// Per articulated model, under ~<model>/: sensor_msgs/JointState out and in.
inline constexpr char kJointStatesTopic[] = "joint_states";
inline constexpr char kJointCommandTopic[] = "joint_command";
inline constexpr char kJointTrajectoryTopic[] = "joint_trajectory";

// Global topics (tf2_ros's broadcasters publish /tf and /tf_static).
inline constexpr char kTfTopic[] = "/tf";
inline constexpr char kTfStaticTopic[] = "/tf_static";
inline constexpr char kClockTopic[] = "/clock";
inline constexpr char kUseSimTimeParam[] = "/use_sim_time";

// The infinite ground plane's name in contacts; no model may take it.
inline constexpr char kGroundName[] = "ground";
// Separates the model and the link in frame names: '<model>/<link>'.
inline constexpr char kFrameSeparator = '/';

}  // namespace rigid_body_sim::node::names

#endif  // RIGID_BODY_SIM_NODE_NAMES_H_
