// The simulator node: owns the world and the model registry, steps the world
// in its own thread, and serves and publishes everything in names.h.
#ifndef RIGID_BODY_SIM_NODE_SIM_NODE_H_
#define RIGID_BODY_SIM_NODE_SIM_NODE_H_

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <trajectory_msgs/JointTrajectory.h>
#include <visualization_msgs/MarkerArray.h>
#include <boost/thread/recursive_mutex.hpp>

#include "rigid_body_sim/ApplyWrench.h"
#include "rigid_body_sim/Contacts.h"
#include "rigid_body_sim/Delete.h"
#include "rigid_body_sim/GetModelProperties.h"
#include "rigid_body_sim/GetPhysics.h"
#include "rigid_body_sim/GetState.h"
#include "rigid_body_sim/GetWorldProperties.h"
#include "rigid_body_sim/ModelStates.h"
#include "rigid_body_sim/PhysicsConfig.h"
#include "rigid_body_sim/RayCast.h"
#include "rigid_body_sim/SetJointState.h"
#include "rigid_body_sim/SetPhysics.h"
#include "rigid_body_sim/SetState.h"
#include "rigid_body_sim/Spawn.h"
#include "rigid_body_sim/Step.h"
#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/node/joint_requests.h"
#include "rigid_body_sim/node/joint_trajectory.h"
#include "rigid_body_sim/node/model_registry.h"
#include "rigid_body_sim/node/options.h"
#include "rigid_body_sim/node/sensor_models.h"
#include "rigid_body_sim/node/sim_diagnostics.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::node {

struct ModelSensors;
struct DriveCommand;
struct RunningLaser;
struct RunningImu;
struct RunningBumper;
struct RunningForceTorque;
struct RunningOdometry;
struct RunningDiffDrive;

// Thread model: ROS callbacks run on an AsyncSpinner's threads, the world
// steps in the loop thread, and one mutex serialises every access to the
// world, the registry and the node's state. A step holds the mutex, so a
// spawn, delete or teleport happens between two steps, and every service
// answers after its effect. URDF parsing and hull building happen before the
// mutex is taken. Messages are built under the mutex and published after.
class SimNode {
 public:
  SimNode(NodeOptions options, ros::NodeHandle node, ros::NodeHandle private_node);
  ~SimNode();
  SimNode(const SimNode&) = delete;
  SimNode& operator=(const SimNode&) = delete;

  // Adds the ground plane, spawns ~models, advertises the topics and
  // services and starts stepping. Fails naming the first model that could
  // not be spawned.
  physics::Status Start();

 private:
  // A force and torque applied for a number of steps.
  struct ActiveWrench {
    physics::BodyId body;
    physics::Vec3 force_world;   // N
    physics::Vec3 point_world;   // m
    physics::Vec3 torque_world;  // N m
    std::int64_t remaining_steps = 0;
  };
  // Messages built under the mutex, published after it is released.
  struct Outbox {
    std::optional<tf2_msgs::TFMessage> tf;
    std::optional<tf2_msgs::TFMessage> tf_static;
    std::optional<rigid_body_sim::ModelStates> states;
    std::optional<rigid_body_sim::Contacts> contacts;
    std::optional<visualization_msgs::MarkerArray> contact_markers;
    std::optional<visualization_msgs::MarkerArray> body_markers;
    std::vector<std::pair<std::string, sensor_msgs::JointState>> joint_states;  // by model
    std::optional<double> clock;                                                // s of sim time
    bool diagnostics = false;  // a diagnostics window closed
    // The sensors' messages, each bound to its publisher.
    std::vector<std::function<void()>> sensors;
    bool tf_is_new_frame = false;   // tf holds only the frames of a new model
    std::uint64_t reset_count = 0;  // resets before the messages were built
  };
  using Clock = std::chrono::steady_clock;

  void AdvertiseServices();

  // Locks the world mutex, telling the step loop to let the caller in first.
  std::unique_lock<std::mutex> LockWorld();

  struct SpawnedModel {
    std::vector<std::string> frames;   // tf frames of its links
    std::vector<std::string> ignored;  // elements of the description not simulated
  };
  physics::Result<SpawnedModel> SpawnModel(const ModelSpec& spec);
  // What SpawnModel makes of a spec before it locks the world.
  struct PreparedModel {
    io::LoadedModel loaded;
    physics::BodyDef def;
    std::optional<physics::ArticulationDef> articulation;
    Model model;  // its fields from the spec and the URDF; bodies not yet made
    std::vector<visualization_msgs::Marker> markers;
    std::vector<std::string> warnings;
  };
  physics::Result<PreparedModel> PrepareModel(const ModelSpec& spec,
                                              const MaterialDefaults& defaults) const;
  // Adds the prepared model to the world and the registry; its tf frames.
  physics::Result<std::vector<std::string>> CommitModelLocked(const ModelSpec& spec,
                                                              PreparedModel* prepared,
                                                              Outbox* outbox);
  // The name and the robot namespace are free.
  physics::Status CheckNamesFreeLocked(const ModelSpec& spec) const;
  std::string DescribeOverlaps(const std::string& model_name);
  physics::Result<io::LoadedModel> LoadModel(const ModelSpec& spec) const;
  physics::Status CreateBodyLocked(const physics::BodyDef& def, const io::LoadedModel& loaded,
                                   Model* model);
  physics::Status CreateArticulationLocked(const physics::ArticulationDef& def,
                                           const io::LoadedModel& loaded, Model* model);
  // The articulated models' topics (sim_joints.cc): ~<model>/joint_states
  // and ~<model>/joint_command.
  void AdvertiseJointTopicsLocked(const Model& model);
  // Takes the model's topics out of joint_topics_, under the world lock;
  // DestroyRetiredJointTopics destroys them after it is released.
  // Destroying a subscriber waits for its running callback, and a
  // joint_command callback waits for the world lock: destroyed under it,
  // a command arriving with the delete would deadlock the node.
  void RemoveJointTopics(const std::string& model_name);
  void DestroyRetiredJointTopics();
  // The joint topics' callbacks: `joints` is what the model was spawned
  // with; a message for a model since deleted (or spawned anew under the
  // same name) finds another `articulation` and is dropped.
  void OnJointCommand(const std::shared_ptr<const ModelJoints>& joints,
                      physics::ArticulationId articulation, const sensor_msgs::JointState& command);
  void OnJointTrajectory(const std::shared_ptr<const ModelJoints>& joints,
                         physics::ArticulationId articulation,
                         const trajectory_msgs::JointTrajectory& trajectory);
  bool IsSameModelLocked(const std::string& model_name, physics::ArticulationId articulation) const;
  // Runs a topic or timer callback so that no exception leaves it: roscpp
  // would end the process. A throw is logged with `what` and dropped.
  template <typename Callback>
  void Guarded(const char* what, const Callback& callback);
  // Before each step: every active trajectory's position and velocity at
  // the step's end become its joints' servo commands.
  void FollowTrajectoriesLocked();
  bool OnSetJointState(rigid_body_sim::SetJointState::Request& request,
                       rigid_body_sim::SetJointState::Response& response);
  void FillJointStatesLocked(const ros::Time& stamp, Outbox* outbox) const;
  void PublishJointStates(const Outbox& outbox);
  // Puts an articulated model's joints back where it spawned, at rest,
  // with no command.
  physics::Status ResetJointsLocked(const Model& model);
  // The servos of every joint that mimics none hold its spawn position.
  void HoldJointsLocked(const Model& model);

  bool OnSpawn(rigid_body_sim::Spawn::Request& request, rigid_body_sim::Spawn::Response& response);
  bool OnDelete(rigid_body_sim::Delete::Request& request,
                rigid_body_sim::Delete::Response& response);
  // World services (sim_world_services.cc): introspection and the resets.
  bool OnResetSimulation(std_srvs::Trigger::Request& request,
                         std_srvs::Trigger::Response& response);
  bool OnResetWorld(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool OnGetWorldProperties(rigid_body_sim::GetWorldProperties::Request& request,
                            rigid_body_sim::GetWorldProperties::Response& response);
  bool OnGetModelProperties(rigid_body_sim::GetModelProperties::Request& request,
                            rigid_body_sim::GetModelProperties::Response& response);
  // Every model back to its spawn state, wrenches dropped; sim time back to 0
  // unless keep_time. Returns the reply's message.
  std::string Reset(bool keep_time);
  bool OnSetPaused(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response);
  bool OnStep(rigid_body_sim::Step::Request& request, rigid_body_sim::Step::Response& response);
  bool OnGetState(rigid_body_sim::GetState::Request& request,
                  rigid_body_sim::GetState::Response& response);
  // sim_ray_cast.cc
  bool OnRayCast(rigid_body_sim::RayCast::Request& request,
                 rigid_body_sim::RayCast::Response& response);
  bool OnSetState(rigid_body_sim::SetState::Request& request,
                  rigid_body_sim::SetState::Response& response);
  bool OnApplyWrench(rigid_body_sim::ApplyWrench::Request& request,
                     rigid_body_sim::ApplyWrench::Response& response);
  bool OnGetPhysics(rigid_body_sim::GetPhysics::Request& request,
                    rigid_body_sim::GetPhysics::Response& response);
  bool OnSetPhysics(rigid_body_sim::SetPhysics::Request& request,
                    rigid_body_sim::SetPhysics::Response& response);
  bool OnCancelStep(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  // Advertises `method` as service `name`, answering success = false with
  // the reason when it throws (or failing the call for a response without
  // success), so that no exception leaves a callback.
  template <typename Request, typename Response>
  ros::ServiceServer Advertise(const char* name,
                               bool (SimNode::*method)(Request& request, Response& response));
  void OnBodyMarkersSubscriber(const ros::SingleSubscriberPublisher& publisher);

  // Live parameters (sim_reconfigure.cc). The dynamic_reconfigure server
  // takes its own mutex, then the world's; nothing takes them the other way
  // round (PushReconfigureConfig runs without the world lock).
  void StartReconfigure();
  void OnReconfigure(rigid_body_sim::PhysicsConfig& config, std::uint32_t level);
  // Shows the running values in the server (after ~set_physics).
  void PushReconfigureConfig();
  // Validated settings into the world and the loop; the caller wakes it.
  physics::Status ApplyLiveSettingsLocked(const LiveSettings& settings);

  // The URDF's Gazebo sensors and plugins (sim_sensors.cc): made at
  // spawn, their topics under the plugin's or the model's robot namespace.
  physics::Result<std::unique_ptr<ModelSensors>> MakeSensorsLocked(
      const Model& model, const io::GazeboPlugins& plugins);
  ros::NodeHandle SensorHandle(const Model& model, const io::PluginCommon& common) const;
  // Messages a sensor's publisher holds: a ~step call publishes a chunk's
  // readings at once (100 IMU readings for a second at 100 Hz).
  static constexpr int kSensorQueue = 100;
  // The sensor's topic in its namespace.
  template <typename Message>
  ros::Publisher AdvertiseSensor(const Model& model, const io::PluginCommon& common) const {
    return SensorHandle(model, common).advertise<Message>(common.topic, kSensorQueue);
  }
  physics::Status AddLasersLocked(const Model& model, const io::GazeboPlugins& plugins,
                                  ModelSensors* sensors);
  physics::Status AddInertialSensorsLocked(const Model& model, const io::GazeboPlugins& plugins,
                                           ModelSensors* sensors);
  physics::Status AddDrivesLocked(const Model& model, const io::GazeboPlugins& plugins,
                                  ModelSensors* sensors);
  void OnDriveCommand(const geometry_msgs::Twist& twist, DriveCommand* command);
  // Around each step (sim_sensor_readings.cc): the states the readings
  // difference and the drives' wheel commands before it; the readings that
  // are due after it, into pending_sensor_messages_.
  void BeforeStepSensorsLocked();
  void AfterStepSensorsLocked();
  void DriveWheelsLocked(const Model& model, double dt, RunningDiffDrive* drive);
  void ReadLaserLocked(const Model& model, const ros::Time& stamp, RunningLaser* laser);
  void ReadImuLocked(const Model& model, const ros::Time& stamp, RunningImu* imu);
  void ReadBumperLocked(const ros::Time& stamp, const RunningBumper& bumper);
  void ReadForceTorqueLocked(const Model& model, const ros::Time& stamp,
                             const RunningForceTorque& sensor);
  void ReadGroundTruthLocked(const Model& model, const ros::Time& stamp,
                             const RunningOdometry& odometry);
  void ReadDriveOdometryLocked(const Model& model, const ros::Time& stamp, RunningDiffDrive* drive);
  // The drive's odom -> base: the base's true pose, or the encoders'.
  FrameState DriveOdometryLocked(const Model& model, const RunningDiffDrive& drive) const;
  // The drive that publishes the model's odom -> root tf, if any.
  const RunningDiffDrive* RootTfDriveLocked(const Model& model) const;
  // world -> odom -> root in place of world -> root.
  void AppendDriveTfLocked(const Model& model, const RunningDiffDrive& drive,
                           const ros::Time& stamp, tf2_msgs::TFMessage* tf) const;
  void ResetSensorsLocked();

  void StepLoop();
  // The callers of these hold the mutex.
  void StepLocked();
  // Logs and records the bodies the last step froze (World::non_finite_bodies).
  void ReportFrozenLocked();
  void ReanchorLocked();
  // The state of links[link] of the model, from the body that carries it.
  FrameState LinkStateLocked(const Model& model, std::size_t link) const;
  // The stamp of everything published now: sim time when /use_sim_time is
  // true (listeners follow our /clock), wall time otherwise, so that tf
  // listeners never extrapolate.
  ros::Time StampLocked() const;
  // The periodic messages; contacts and the clock only when sim time moved
  // since they were last built, tf too under sim time (tf2 drops a repeated
  // stamp); under wall time tf goes out every period with a new stamp.
  void FillPeriodicLocked(Outbox* outbox);
  // FillPeriodicLocked when the publish period has passed, and the next due
  // time moved on; whether it filled.
  bool FillPeriodicIfDueLocked(Clock::time_point now, Outbox* outbox);
  void FillTfLocked(const ros::Time& stamp, tf2_msgs::TFMessage* tf) const;
  tf2_msgs::TFMessage ModelTfLocked(const Model& model) const;
  void AppendModelTfLocked(const Model& model, const ros::Time& stamp,
                           tf2_msgs::TFMessage* tf) const;
  tf2_msgs::TFMessage StaticTfLocked() const;
  void LogStatusLocked(Clock::time_point now);
  void CloseDiagnosticsWindowLocked(Clock::time_point now);

  void Publish(Outbox outbox);

  const NodeOptions options_;
  io::UrdfLoadOptions load_options_;
  ros::NodeHandle node_;
  ros::NodeHandle private_node_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
  // Replaced on every /tf_static message, under static_mutex_: the
  // broadcaster keeps every frame it was ever given, so a deleted static
  // model would stay in the latched message of a long-lived one.
  std::mutex static_mutex_;
  std::unique_ptr<tf2_ros::StaticTransformBroadcaster> static_broadcaster_;
  ros::Publisher clock_publisher_;
  ros::Publisher states_publisher_;
  ros::Publisher contacts_publisher_;
  ros::Publisher contact_markers_publisher_;
  ros::Publisher body_markers_publisher_;
  std::vector<ros::ServiceServer> services_;
  struct JointTopics {
    // A handle of the model's own: roscpp's NodeHandle keeps a record of
    // every publisher and subscriber made through it until the handle
    // itself goes, so topics made through private_node_ would grow the
    // node by some 300 bytes per spawn of an articulated model.
    ros::NodeHandle handle;
    ros::Publisher states;
    ros::Subscriber command;
    ros::Subscriber trajectory;
  };
  struct ActiveTrajectory {
    std::vector<int> joints;  // indices into the model's joint_names
    // Per entry of `joints`: still driven by this trajectory. A later
    // command or trajectory naming the joint takes it over.
    std::vector<bool> owned;
    JointTrajectory plan;
    double start_time = 0.0;  // s of sim time
  };
  // By model, under mutex_: the trajectories in progress, on disjoint
  // joints, oldest first.
  std::map<std::string, std::vector<ActiveTrajectory>> trajectories_;
  // Takes `joints` of the model from the trajectories in progress; those
  // left with no joint go to `released`, to be freed without the lock.
  void ReleaseJointsLocked(const std::string& model_name, const std::vector<int>& joints,
                           std::vector<ActiveTrajectory>* released);

  std::mutex joint_topics_mutex_;
  std::map<std::string, JointTopics> joint_topics_;  // by model
  std::vector<JointTopics> retired_joint_topics_;    // of deleted models, to destroy
  std::unique_ptr<SimDiagnostics> diagnostics_;
  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<dynamic_reconfigure::Server<rigid_body_sim::PhysicsConfig>> reconfigure_;

  std::mutex mutex_;
  std::condition_variable wake_;  // pause, resume, settings, shutdown
  std::atomic<int> waiting_{0};   // callers blocked in LockWorld
  physics::World world_;
  ModelRegistry registry_;
  std::optional<physics::BodyId> ground_;
  std::vector<ActiveWrench> wrenches_;
  // By model: the running sensors of models that declare any.
  std::map<std::string, std::unique_ptr<ModelSensors>> sensors_;
  std::vector<std::function<void()>> pending_sensor_messages_;
  SensorNoise noise_;
  // By model; shared, so that a new subscriber's copy (a static terrain's
  // markers hold millions of points) is made without the world lock.
  using MarkerList = std::shared_ptr<const std::vector<visualization_msgs::Marker>>;
  std::map<std::string, MarkerList> body_markers_;
  std::set<std::string> frozen_models_;  // frozen by the step guard, until set_state or reset
  bool paused_ = false;
  // A ~step call runs in chunks; between them ~cancel_step can stop it.
  std::mutex step_service_mutex_;  // one ~step call at a time
  bool step_in_progress_ = false;
  std::string cancel_step_;  // the service that stops the ~step call in progress, if any
  bool shutdown_ = false;
  LiveSettings live_;                 // what ~set_physics and dynamic_reconfigure change
  double last_periodic_time_ = -1.0;  // sim time of the last tf and contacts
  int contact_marker_count_ = 0;      // contacts drawn in the last contact markers
  std::uint64_t steps_ = 0;
  // Pacing: sim time anchor_sim_ is due at wall time anchor_wall_.
  Clock::time_point anchor_wall_;
  double anchor_sim_ = 0.0;
  // When the loop next publishes; a new ~publish_rate takes effect at once.
  Clock::time_point next_publish_;
  Clock::time_point status_wall_;
  double status_sim_ = 0.0;

  std::mutex clock_mutex_;  // keeps /clock monotonic between resets
  double last_clock_ = 0.0;
  std::uint64_t reset_count_ = 0;  // guarded by mutex_
  // Keeps /tf stamps monotonic between resets, and drops messages built
  // before a reset.
  std::mutex publish_mutex_;
  std::uint64_t tf_reset_count_ = 0;
  ros::Time last_tf_stamp_;

  std::thread loop_thread_;
};

template <typename Callback>
void SimNode::Guarded(const char* what, const Callback& callback) {
  try {
    callback();
  } catch (const std::exception& error) {
    ROS_ERROR("%s: dropped after an internal error: %s", what, error.what());
  }
}

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_SIM_NODE_H_
