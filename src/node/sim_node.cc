// The node's set-up and spawning; its services, loop and publishing are in
// sim_node_services.cc, sim_loop.cc and sim_publishing.cc.
#include "rigid_body_sim/node/sim_node.h"

#include <cassert>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include <rosgraph_msgs/Clock.h>

#include "node/model_sensors.h"
#include "node/ros_uri.h"
#include "rigid_body_sim/io/mesh_process.h"
#include "rigid_body_sim/io/xacro_process.h"
#include "rigid_body_sim/node/msg_conversion.h"
#include "rigid_body_sim/node/names.h"

namespace rigid_body_sim::node {

using physics::BodyId;
using physics::Result;
using physics::Status;

namespace {

// The mesh helper is built next to the node (devel/lib/rigid_body_sim, or
// the installed package's lib directory).
// A program installed beside the node (the mesh helper, the xacro expander).
std::string BesideNode(const std::string& name) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  return (self.parent_path() / name).string();
}

}  // namespace

SimNode::SimNode(NodeOptions options, ros::NodeHandle node, ros::NodeHandle private_node)
    : options_(std::move(options)),
      node_(std::move(node)),
      private_node_(std::move(private_node)),
      world_(options_.world),
      noise_(static_cast<std::uint64_t>(options_.sensor_noise_seed)),
      paused_(options_.paused),
      live_(LiveSettingsOf(options_)) {
  load_options_.default_density = options_.default_density;
  load_options_.balance_inertia = options_.balance_inertia;
  load_options_.hull.max_vertices = options_.max_hull_vertices;
  load_options_.max_links = options_.max_links_per_model;
  load_options_.max_joints = options_.max_joints_per_model;
  load_options_.max_file_bytes = static_cast<std::uintmax_t>(options_.max_file_bytes);
  // Meshes are untrusted files: assimp and qhull run in the helper process.
  io::MeshProcessLimits mesh_limits;
  mesh_limits.helper_path = BesideNode("rigid_body_sim_mesh_helper");
  mesh_limits.memory_bytes = static_cast<std::uint64_t>(options_.mesh_memory_limit);
  mesh_limits.cpu_seconds = options_.mesh_cpu_limit;
  mesh_limits.max_file_bytes = static_cast<std::uint64_t>(options_.max_file_bytes);
  mesh_limits.max_triangles = static_cast<std::uint64_t>(options_.max_mesh_triangles);
  load_options_.mesh_hull_loader = [mesh_limits](const std::string& path,
                                                 const physics::Vec3& scale,
                                                 const io::HullOptions& hull) {
    return io::CachedMeshHull(path, scale, hull, mesh_limits);
  };
  load_options_.mesh_triangles_loader = [mesh_limits](const std::string& path,
                                                      const physics::Vec3& scale) {
    return io::CachedMeshTriangles(path, scale, mesh_limits);
  };
  // Concave moving meshes: decomposed in the helper, results kept on disk.
  const std::string cache_directory = io::DefaultDecompositionCacheDirectory();
  load_options_.mesh_pieces_loader = [mesh_limits, cache_directory](
                                         const std::string& path, const physics::Vec3& scale,
                                         const io::DecompositionOptions& decomposition,
                                         io::PiecesRule rule) {
    io::MeshPiecesRequest request;
    request.path = path;
    request.scale = scale;
    request.options = decomposition;
    request.rule = rule;
    request.cache_directory = cache_directory;
    return io::CachedMeshPieces(request, mesh_limits);
  };
  load_options_.resolver = ResolveRosUri;
  // Movable joints are simulated: a model with any becomes an articulation.
  load_options_.articulate = true;
}

SimNode::~SimNode() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    shutdown_ = true;
  }
  wake_.notify_all();
  if (loop_thread_.joinable()) loop_thread_.join();
}

std::unique_lock<std::mutex> SimNode::LockWorld() {
  waiting_.fetch_add(1, std::memory_order_acq_rel);
  std::unique_lock<std::mutex> lock(mutex_);
  waiting_.fetch_sub(1, std::memory_order_acq_rel);
  return lock;
}

namespace {

// Whether a service response has the success and message fields.
template <typename Response, typename = void>
struct HasSuccess : std::false_type {};
template <typename Response>
struct HasSuccess<Response, std::void_t<decltype(std::declval<Response&>().success),
                                        decltype(std::declval<Response&>().message)>>
    : std::true_type {};

}  // namespace

template <typename Request, typename Response>
ros::ServiceServer SimNode::Advertise(const char* name,
                                      bool (SimNode::*method)(Request& request,
                                                              Response& response)) {
  const boost::function<bool(Request&, Response&)> guarded =
      [this, method, name](Request& request, Response& response) {
        try {
          return (this->*method)(request, response);
        } catch (const std::exception& error) {
          ROS_ERROR("~%s: %s", name, error.what());
          response = Response();
          if constexpr (HasSuccess<Response>::value) {
            response.success = false;
            response.message = std::string("internal error: ") + error.what();
            return true;
          } else {
            return false;  // no field to say why: the call fails
          }
        }
      };
  return private_node_.advertiseService<Request, Response>(name, guarded);
}

Status SimNode::Start() {
  tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
  static_broadcaster_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
  if (options_.use_sim_time) {
    clock_publisher_ = node_.advertise<rosgraph_msgs::Clock>(names::kClockTopic, 10);
  }
  states_publisher_ = private_node_.advertise<rigid_body_sim::ModelStates>(names::kStatesTopic, 10);
  contacts_publisher_ =
      private_node_.advertise<rigid_body_sim::Contacts>(names::kContactsTopic, 100);
  contact_markers_publisher_ =
      private_node_.advertise<visualization_msgs::MarkerArray>(names::kContactMarkersTopic, 10);
  body_markers_publisher_ = private_node_.advertise<visualization_msgs::MarkerArray>(
      names::kBodyMarkersTopic, 100, [this](const ros::SingleSubscriberPublisher& publisher) {
        OnBodyMarkersSubscriber(publisher);
      });

  diagnostics_ = std::make_unique<SimDiagnostics>(node_, private_node_);

  if (options_.ground_plane) {
    physics::BodyDef ground;
    ground.is_static = true;
    physics::ShapeDef plane;
    plane.geometry = physics::HalfSpace{};
    plane.material.friction = options_.ground_friction;
    plane.material.restitution = options_.ground_restitution;
    ground.shapes.push_back(plane);
    Result<BodyId> id = world_.CreateBody(ground);
    if (!id.ok()) return Status::Error("ground plane: " + id.message());
    ground_ = *id;
    body_markers_[names::kGroundName] =
        std::make_shared<const std::vector<visualization_msgs::Marker>>(
            ShapeMarkers(ground.shapes, names::kGroundName, options_.world_frame));
  }

  for (const ModelSpec& spec : options_.models) {
    Result<SpawnedModel> spawned = SpawnModel(spec);
    if (!spawned.ok()) {
      return Status::Error("~models: cannot spawn '" + spec.name + "': " + spawned.message());
    }
  }

  // Before the services: ~set_physics updates the reconfigure server, so
  // it must exist by the time the first call can arrive.
  StartReconfigure();
  AdvertiseServices();

  {
    std::lock_guard<std::mutex> lock(mutex_);
    ReanchorLocked();
    next_publish_ = Clock::now();
    // The frames spawned so far went out with the current stamp already.
    last_periodic_time_ = world_.time();
    status_wall_ = Clock::now();
    status_sim_ = world_.time();
  }
  loop_thread_ = std::thread([this] { StepLoop(); });
  ROS_INFO("rigid_body_sim: %zu models, time step %g s, real-time factor %g%s, world frame '%s'",
           options_.models.size(), live_.time_step, live_.real_time_factor,
           options_.paused ? ", paused" : "", options_.world_frame.c_str());
  return Status::Ok();
}

void SimNode::AdvertiseServices() {
  using Self = SimNode;
  services_.push_back(Advertise(names::kSpawnService, &Self::OnSpawn));
  services_.push_back(Advertise(names::kDeleteService, &Self::OnDelete));
  services_.push_back(Advertise(names::kResetService, &Self::OnResetSimulation));
  services_.push_back(Advertise(names::kResetSimulationService, &Self::OnResetSimulation));
  services_.push_back(Advertise(names::kResetWorldService, &Self::OnResetWorld));
  services_.push_back(Advertise(names::kGetWorldPropertiesService, &Self::OnGetWorldProperties));
  services_.push_back(Advertise(names::kGetModelPropertiesService, &Self::OnGetModelProperties));
  services_.push_back(Advertise(names::kSetPausedService, &Self::OnSetPaused));
  services_.push_back(Advertise(names::kStepService, &Self::OnStep));
  services_.push_back(Advertise(names::kCancelStepService, &Self::OnCancelStep));
  services_.push_back(Advertise(names::kGetStateService, &Self::OnGetState));
  services_.push_back(Advertise(names::kRayCastService, &Self::OnRayCast));
  services_.push_back(Advertise(names::kSetStateService, &Self::OnSetState));
  services_.push_back(Advertise(names::kSetJointStateService, &Self::OnSetJointState));
  services_.push_back(Advertise(names::kApplyWrenchService, &Self::OnApplyWrench));
  services_.push_back(Advertise(names::kGetPhysicsService, &Self::OnGetPhysics));
  services_.push_back(Advertise(names::kSetPhysicsService, &Self::OnSetPhysics));
}

Result<io::LoadedModel> SimNode::LoadModel(const ModelSpec& spec) const {
  io::UrdfLoadOptions options = load_options_;
  options.joint_positions = spec.joint_positions;
  options.spawn_static = spec.is_static;
  if (spec.urdf.size() > options.max_file_bytes) {
    // The same bound as a URDF file's, before the XML parser sees it.
    return Result<io::LoadedModel>::Error("urdf has " + std::to_string(spec.urdf.size()) +
                                          " bytes, more than ~max_file_bytes " +
                                          std::to_string(options.max_file_bytes));
  }
  io::XacroRequest xacro;
  xacro.script = BesideNode("xacro");
  xacro.args = spec.xacro_args;
  xacro.limits.memory_bytes = static_cast<std::uint64_t>(options_.mesh_memory_limit);
  xacro.limits.cpu_seconds = options_.mesh_cpu_limit;
  xacro.limits.max_file_bytes = static_cast<std::uint64_t>(options_.max_file_bytes);
  options.xacro_expander = [xacro](const std::string& path, const std::string& text) {
    return path.empty() ? io::ExpandXacroText(text, xacro) : io::ExpandXacroFile(path, xacro);
  };
  if (!spec.urdf.empty()) return io::LoadUrdfString(spec.urdf, options);
  if (spec.urdf_path.empty()) {
    return Result<io::LoadedModel>::Error("neither urdf nor urdf_path is given");
  }
  Result<std::string> path = ResolveRosUri(spec.urdf_path);
  if (!path.ok()) return path.status();
  return io::LoadUrdfFile(*path, options);
}

namespace {

// The collision shapes of a model being spawned: for an articulated one, a
// marker per shape in its link's frame, ids running on across the links so
// that none replaces another; else the body's shapes in its root frame.
std::vector<visualization_msgs::Marker> SpawnMarkers(const Model& model,
                                                     const io::LoadedModel& loaded,
                                                     const physics::BodyDef& def,
                                                     const physics::ArticulationDef* articulation) {
  if (articulation == nullptr) {
    return ShapeMarkers(def.shapes, model.name, TfFrame(model, loaded.root_link));
  }
  std::vector<visualization_msgs::Marker> markers;
  for (const physics::LinkDef& link : articulation->links) {
    for (visualization_msgs::Marker& marker :
         ShapeMarkers(link.shapes, model.name, TfFrame(model, link.name))) {
      marker.id = static_cast<int>(markers.size());
      markers.push_back(std::move(marker));
    }
  }
  return markers;
}

}  // namespace

// Load, convert, commit, announce: the model is read and turned into its
// definitions before the world is locked, added under the lock, and its
// messages go out after.
Result<SimNode::SpawnedModel> SimNode::SpawnModel(const ModelSpec& spec) {
  if (Status status = ValidateModelName(spec.name); !status.ok()) return status;
  MaterialDefaults defaults;
  {
    // Early refusal of a taken name spares loading the model; the name is
    // checked again when the body is added.
    std::unique_lock<std::mutex> lock = LockWorld();
    if (Status status = CheckNamesFreeLocked(spec); !status.ok()) return status;
    defaults = live_.defaults;
  }
  Result<PreparedModel> prepared = PrepareModel(spec, defaults);
  if (!prepared.ok()) return prepared.status();
  Outbox outbox;
  outbox.body_markers.emplace().markers = prepared->markers;
  std::vector<std::string> frames;
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    Result<std::vector<std::string>> committed =
        CommitModelLocked(spec, &prepared.value(), &outbox);
    if (!committed.ok()) return committed.status();
    frames = std::move(committed).value();
  }
  Publish(std::move(outbox));
  for (const std::string& warning : prepared->warnings) {
    ROS_WARN("model '%s': %s", spec.name.c_str(), warning.c_str());
  }
  const PreparedModel& made = *prepared;
  ROS_INFO("spawned '%s' (%s, %zu shapes, %zu frames)", spec.name.c_str(),
           made.articulation ? (made.articulation->fixed_base ? "articulated, fixed base"
                                                              : "articulated, floating base")
                             : (made.def.is_static ? "static" : "dynamic"),
           made.def.shapes.size(), frames.size());
  return SpawnedModel{std::move(frames), made.loaded.ignored};
}

Status SimNode::CheckNamesFreeLocked(const ModelSpec& spec) const {
  if (registry_.Find(spec.name) != nullptr) {
    return Status::Error("a model named '" + spec.name + "' already exists");
  }
  const Result<std::string> robot_namespace = ResolveRobotNamespace(spec.robot_namespace);
  if (!robot_namespace.ok()) return robot_namespace.status();
  if (robot_namespace->empty()) return Status::Ok();
  // Two models' joint topics in one namespace would read each other's
  // commands and interleave their joint_states.
  for (const auto& [name, model] : registry_.models()) {
    if (model.robot_namespace == *robot_namespace) {
      return Status::Error("robot_namespace '" + *robot_namespace + "' is taken by model '" + name +
                           "'");
    }
  }
  return Status::Ok();
}

Result<SimNode::PreparedModel> SimNode::PrepareModel(const ModelSpec& spec,
                                                     const MaterialDefaults& defaults) const {
  Result<io::LoadedModel> loaded = LoadModel(spec);
  if (!loaded.ok()) return loaded.status();
  PreparedModel prepared;
  prepared.warnings = loaded->warnings;
  Result<physics::BodyDef> def = MakeBodyDef(*loaded, spec, defaults);
  if (!def.ok()) return def.status();
  prepared.def = std::move(def).value();
  if (loaded->articulated) {
    Result<physics::ArticulationDef> made =
        MakeArticulationSpec(*loaded, spec, prepared.def, &prepared.warnings);
    if (!made.ok()) return made.status();
    prepared.articulation = std::move(made).value();
  }
  prepared.model.name = spec.name;
  prepared.model.robot_namespace = ResolveRobotNamespace(spec.robot_namespace).value();
  prepared.model.tf_prefix = ResolveTfPrefix(spec.name, spec.tf_prefix, spec.tf_mode).value();
  prepared.model.tf_mode = spec.tf_mode;
  prepared.model.hold = spec.hold;
  prepared.model.world_link = loaded->world_link;
  if (loaded->world_link && spec.tf_mode == TfMode::kRoot &&
      !(spec.root_state.world_from_frame.translation.isZero() &&
        spec.root_state.world_from_frame.rotation.isApprox(physics::Quat::Identity(), 0.0))) {
    prepared.warnings.push_back(
        "tf_mode root: robot_state_publisher places the links from the URDF's 'world' link, "
        "which tf takes as the world frame, while the model was spawned away from it; spawn it "
        "at the identity pose, or give the URDF no 'world' link");
  }
  prepared.model.links = loaded->links;
  prepared.model.joints = loaded->joints;
  // An arm fixed to the world moves all the same: its mass is its links'.
  prepared.model.mass = prepared.def.is_static ? 0.0 : prepared.def.mass_properties.mass;
  if (prepared.articulation) {
    prepared.model.mass = 0.0;
    for (const io::LinkFrame& link : loaded->links) prepared.model.mass += link.mass;
  }
  prepared.model.spawn_state = FrameState{
      prepared.def.world_from_body, prepared.def.linear_velocity, prepared.def.angular_velocity};
  // The markers hold every triangle of a static mesh (6 M points for a
  // 2 M-triangle terrain): built before the world is locked.
  prepared.markers = SpawnMarkers(prepared.model, *loaded, prepared.def,
                                  prepared.articulation ? &*prepared.articulation : nullptr);
  prepared.loaded = std::move(loaded).value();
  return prepared;
}

Result<std::vector<std::string>> SimNode::CommitModelLocked(const ModelSpec& spec,
                                                            PreparedModel* prepared,
                                                            Outbox* outbox) {
  if (Status status = CheckNamesFreeLocked(spec); !status.ok()) return status;
  Model model = prepared->model;
  const Status created =
      prepared->articulation
          ? CreateArticulationLocked(*prepared->articulation, prepared->loaded, &model)
          : CreateBodyLocked(prepared->def, prepared->loaded, &model);
  if (!created.ok()) return created;
  Result<std::unique_ptr<ModelSensors>> sensors =
      MakeSensorsLocked(model, prepared->loaded.plugins);
  if (!sensors.ok()) {
    const Status removed = model.articulation.IsValid()
                               ? world_.DestroyArticulation(model.articulation)
                               : world_.DestroyBody(model.body);
    assert(removed.ok());
    RemoveJointTopics(spec.name);
    return sensors.status();
  }
  if (!(*sensors)->empty()) sensors_[spec.name] = std::move(sensors).value();
  std::vector<std::string> frames;
  for (const io::LinkFrame& link : model.links) frames.push_back(TfFrame(model, link.link_name));
  body_markers_[spec.name] =
      std::make_shared<const std::vector<visualization_msgs::Marker>>(std::move(prepared->markers));
  const Status added = registry_.Add(std::move(model));
  assert(added.ok());
  const Model& stored = *registry_.Find(spec.name);
  if (stored.is_static || stored.articulation.IsValid()) outbox->tf_static = StaticTfLocked();
  if (!stored.is_static) {
    outbox->tf = ModelTfLocked(stored);
    outbox->tf_is_new_frame = true;
    outbox->reset_count = reset_count_;
  }
  return frames;
}

// A rigid model: one body, every link a frame of it.
Status SimNode::CreateBodyLocked(const physics::BodyDef& def, const io::LoadedModel& loaded,
                                 Model* model) {
  Result<BodyId> body = world_.CreateBody(def);
  if (!body.ok()) return body.status();
  model->body = *body;
  model->bodies = {*body};
  model->is_static = def.is_static;
  model->body_shape_links.emplace_back();
  for (const io::LoadedShape& shape : loaded.shapes) {
    model->body_shape_links.back().push_back(shape.link_name);
  }
  for (const io::LinkFrame& link : loaded.links) {
    model->link_body.push_back(0);
    model->body_from_link.push_back(link.root_from_link);
  }
  return Status::Ok();
}

// An articulated model: one body per articulation link (a group of URDF
// links joined by fixed joints); each URDF link is a frame of its group's
// body. Its links move even when its base is fixed, so it is never static.
Status SimNode::CreateArticulationLocked(const physics::ArticulationDef& def,
                                         const io::LoadedModel& loaded, Model* model) {
  Result<physics::ArticulationId> id = world_.CreateArticulation(def);
  if (!id.ok()) return id.status();
  model->articulation = *id;
  const Status gains = world_.SetServoGains(*id, options_.servo);
  assert(gains.ok());
  model->bodies = world_.ArticulationLinks(*id);
  model->body = model->bodies.front();
  model->is_static = false;
  std::map<std::string, int> group_of_link;
  for (std::size_t g = 0; g < def.links.size(); ++g) group_of_link[def.links[g].name] = g;
  for (const io::JointInfo& joint : loaded.joints) {
    if (joint.type == "fixed") {
      group_of_link[joint.child_link] = group_of_link.at(joint.parent_link);
    } else {
      model->joint_names.push_back(joint.name);
      model->spawn_joint_positions.push_back(joint.position);
    }
  }
  model->body_shape_links.resize(def.links.size());
  for (const io::LoadedShape& shape : loaded.shapes) {
    model->body_shape_links[group_of_link.at(shape.link_name)].push_back(shape.link_name);
  }
  std::map<std::string, const io::LinkFrame*> frame_of_link;
  for (const io::LinkFrame& link : loaded.links) frame_of_link[link.link_name] = &link;
  for (const io::LinkFrame& link : loaded.links) {
    const int group = group_of_link.at(link.link_name);
    model->link_body.push_back(group);
    model->body_from_link.push_back(
        frame_of_link.at(def.links[group].name)->root_from_link.Inverse() * link.root_from_link);
  }
  if (model->hold) HoldJointsLocked(*model);
  AdvertiseJointTopicsLocked(*model);
  return Status::Ok();
}

}  // namespace rigid_body_sim::node
