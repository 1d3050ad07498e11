#include "rigid_body_sim/node/sim_node.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include <ros/package.h>
#include <rosgraph_msgs/Clock.h>

#include "rigid_body_sim/node/msg_conversion.h"
#include "rigid_body_sim/node/names.h"

namespace rigid_body_sim::node {

using physics::BodyId;
using physics::Pose;
using physics::FormatNumber;
using physics::Result;
using physics::Status;
using physics::Vec3;

namespace {

// A sim loop that falls this far behind its real-time schedule stops trying
// to catch up and restarts its schedule, so it never steps in bursts.
constexpr double kMaxLagSeconds = 0.1;
// /clock is published at most this often (s of real time) while stepping.
constexpr double kClockPeriodSeconds = 0.001;
constexpr char kPackageScheme[] = "package://";
constexpr char kFileScheme[] = "file://";

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

// package://<package>/<path> through roslib, file://<path> and plain paths
// as they are.
Result<std::string> ResolveRosUri(const std::string& uri) {
  if (StartsWith(uri, kFileScheme)) return uri.substr(std::string(kFileScheme).size());
  if (!StartsWith(uri, kPackageScheme)) return uri;
  const std::string rest = uri.substr(std::string(kPackageScheme).size());
  const std::size_t slash = rest.find('/');
  const std::string package = rest.substr(0, slash);
  if (package.empty()) return Result<std::string>::Error("URI '" + uri + "' names no package");
  // rospack keeps global state; calls are serialised.
  static std::mutex rospack_mutex;
  std::string package_path;
  {
    std::lock_guard<std::mutex> lock(rospack_mutex);
    package_path = ros::package::getPath(package);
  }
  if (package_path.empty()) {
    return Result<std::string>::Error("package '" + package + "' of URI '" + uri +
                                      "' is not found");
  }
  return slash == std::string::npos ? package_path : package_path + rest.substr(slash);
}

template <typename Response>
bool Fail(Response& response, const std::string& message, const char* service) {
  response.success = false;
  response.message = message;
  ROS_WARN("~%s refused: %s", service, message.c_str());
  return true;
}

}  // namespace

SimNode::SimNode(NodeOptions options, ros::NodeHandle node, ros::NodeHandle private_node)
    : options_(std::move(options)),
      node_(std::move(node)),
      private_node_(std::move(private_node)),
      world_(options_.world),
      paused_(options_.paused),
      real_time_factor_(options_.real_time_factor) {
  load_options_.default_density = options_.default_density;
  load_options_.hull.max_vertices = options_.max_hull_vertices;
  load_options_.cylinder_segments = options_.cylinder_segments;
  load_options_.resolver = ResolveRosUri;
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

Status SimNode::Start() {
  tf_publisher_ = node_.advertise<tf2_msgs::TFMessage>(names::kTfTopic, 100);
  tf_static_publisher_ = node_.advertise<tf2_msgs::TFMessage>(names::kTfStaticTopic, 1, true);
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
        ShapeMarkers(ground.shapes, names::kGroundName, options_.world_frame);
  }

  for (const ModelSpec& spec : options_.models) {
    Result<std::vector<std::string>> frames = SpawnModel(spec);
    if (!frames.ok()) {
      return Status::Error("~models: cannot spawn '" + spec.name + "': " + frames.message());
    }
  }

  using Self = SimNode;
  services_.push_back(private_node_.advertiseService(names::kSpawnService, &Self::OnSpawn, this));
  services_.push_back(private_node_.advertiseService(names::kDeleteService, &Self::OnDelete, this));
  services_.push_back(private_node_.advertiseService(names::kResetService, &Self::OnReset, this));
  services_.push_back(
      private_node_.advertiseService(names::kSetPausedService, &Self::OnSetPaused, this));
  services_.push_back(private_node_.advertiseService(names::kStepService, &Self::OnStep, this));
  services_.push_back(
      private_node_.advertiseService(names::kGetStateService, &Self::OnGetState, this));
  services_.push_back(
      private_node_.advertiseService(names::kSetStateService, &Self::OnSetState, this));
  services_.push_back(
      private_node_.advertiseService(names::kApplyWrenchService, &Self::OnApplyWrench, this));
  services_.push_back(
      private_node_.advertiseService(names::kGetPhysicsService, &Self::OnGetPhysics, this));
  services_.push_back(
      private_node_.advertiseService(names::kSetPhysicsService, &Self::OnSetPhysics, this));

  {
    std::lock_guard<std::mutex> lock(mutex_);
    ReanchorLocked();
    // The frames spawned so far went out with the current stamp already.
    last_periodic_time_ = world_.time();
    status_wall_ = Clock::now();
    status_sim_ = world_.time();
  }
  loop_thread_ = std::thread([this] { StepLoop(); });
  ROS_INFO("rigid_body_sim: %zu models, time step %g s, real-time factor %g%s, world frame '%s'",
           options_.models.size(), options_.world.time_step, options_.real_time_factor,
           options_.paused ? ", paused" : "", options_.world_frame.c_str());
  return Status::Ok();
}

// --- spawning -----------------------------------------------------------------

Result<io::LoadedModel> SimNode::LoadModel(const ModelSpec& spec) const {
  if (!spec.urdf.empty()) return io::LoadUrdfString(spec.urdf, load_options_);
  if (spec.urdf_path.empty()) {
    return Result<io::LoadedModel>::Error("neither urdf nor urdf_path is given");
  }
  Result<std::string> path = ResolveRosUri(spec.urdf_path);
  if (!path.ok()) return path.status();
  return io::LoadUrdfFile(*path, load_options_);
}

Result<std::vector<std::string>> SimNode::SpawnModel(const ModelSpec& spec) {
  using FramesResult = Result<std::vector<std::string>>;
  if (Status status = ValidateModelName(spec.name); !status.ok()) return status;
  {
    // Early refusal of a taken name spares loading the model; the name is
    // checked again when the body is added.
    std::unique_lock<std::mutex> lock = LockWorld();
    if (registry_.Find(spec.name) != nullptr) {
      return FramesResult::Error("a model named '" + spec.name + "' already exists");
    }
  }
  Result<io::LoadedModel> loaded = LoadModel(spec);
  if (!loaded.ok()) return loaded.status();
  Result<physics::BodyDef> def = MakeBodyDef(*loaded, spec, options_.defaults);
  if (!def.ok()) return def.status();

  Outbox outbox;
  std::vector<std::string> frames;
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    if (registry_.Find(spec.name) != nullptr) {
      return FramesResult::Error("a model named '" + spec.name + "' already exists");
    }
    Result<BodyId> body = world_.CreateBody(*def);
    if (!body.ok()) return body.status();
    Model model;
    model.name = spec.name;
    model.body = *body;
    model.is_static = def->is_static;
    model.links = loaded->links;
    for (const io::LoadedShape& shape : loaded->shapes)
      model.shape_links.push_back(shape.link_name);
    model.spawn_state =
        FrameState{def->world_from_body, def->linear_velocity, def->angular_velocity};
    for (const io::LinkFrame& link : model.links) {
      frames.push_back(FrameName(spec.name, link.link_name));
    }
    std::vector<visualization_msgs::Marker> markers =
        ShapeMarkers(def->shapes, spec.name, FrameName(spec.name, loaded->root_link));
    outbox.body_markers.emplace().markers = markers;
    body_markers_[spec.name] = std::move(markers);
    const Status added = registry_.Add(std::move(model));
    assert(added.ok());
    const Model& stored = *registry_.Find(spec.name);
    if (stored.is_static) {
      outbox.tf_static = StaticTfLocked();
    } else {
      outbox.tf = ModelTfLocked(stored);
      outbox.tf_is_new_frame = true;
      outbox.reset_count = reset_count_;
    }
  }
  Publish(std::move(outbox));
  for (const std::string& warning : loaded->warnings) {
    ROS_WARN("model '%s': %s", spec.name.c_str(), warning.c_str());
  }
  ROS_INFO("spawned '%s' (%s, %zu shapes, %zu frames)", spec.name.c_str(),
           def->is_static ? "static" : "dynamic", def->shapes.size(), frames.size());
  return frames;
}

// --- services -----------------------------------------------------------------

bool SimNode::OnSpawn(rigid_body_sim::Spawn::Request& request,
                      rigid_body_sim::Spawn::Response& response) {
  Result<ModelSpec> spec = ModelSpecFromMsg(request);
  if (!spec.ok()) return Fail(response, spec.message(), names::kSpawnService);
  Result<std::vector<std::string>> frames = SpawnModel(*spec);
  if (!frames.ok()) {
    return Fail(response, "cannot spawn '" + request.name + "': " + frames.message(),
                names::kSpawnService);
  }
  response.success = true;
  response.message = "spawned '" + request.name + "'";
  response.frames = *frames;
  return true;
}

bool SimNode::OnDelete(rigid_body_sim::Delete::Request& request,
                       rigid_body_sim::Delete::Response& response) {
  Outbox outbox;
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    const Model* model = registry_.Find(request.name);
    if (model == nullptr) {
      return Fail(response, "no model named '" + request.name + "'", names::kDeleteService);
    }
    const BodyId body = model->body;
    const bool was_static = model->is_static;
    const Status destroyed = world_.DestroyBody(body);
    assert(destroyed.ok());
    wrenches_.erase(std::remove_if(wrenches_.begin(), wrenches_.end(),
                                   [body](const ActiveWrench& w) { return w.body == body; }),
                    wrenches_.end());
    registry_.Remove(request.name);
    const int marker_count = static_cast<int>(body_markers_[request.name].size());
    body_markers_.erase(request.name);
    outbox.body_markers.emplace().markers = DeleteMarkers(request.name, marker_count);
    if (was_static) outbox.tf_static = StaticTfLocked();
  }
  Publish(std::move(outbox));
  response.success = true;
  response.message = "deleted '" + request.name + "'";
  return true;
}

bool SimNode::OnReset(std_srvs::Trigger::Request& /*request*/,
                      std_srvs::Trigger::Response& response) {
  Outbox outbox;
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    for (const auto& [name, model] : registry_.models()) {
      const FrameState& state = model.spawn_state;
      const Status status = world_.SetState(model.body, state.world_from_frame,
                                            state.linear_velocity, state.angular_velocity);
      assert(status.ok());
    }
    world_.Restart();
    wrenches_.clear();
    last_periodic_time_ = -1.0;
    ReanchorLocked();
    status_wall_ = Clock::now();
    status_sim_ = 0.0;
    outbox.tf_static = StaticTfLocked();
    FillPeriodicLocked(&outbox);
    {
      std::lock_guard<std::mutex> clock_lock(clock_mutex_);
      last_clock_ = 0.0;
    }
    ++reset_count_;
  }
  wake_.notify_all();
  Publish(std::move(outbox));
  response.success = true;
  response.message = "reset: every model at its spawn state, sim time 0";
  ROS_INFO("%s", response.message.c_str());
  return true;
}

bool SimNode::OnSetPaused(std_srvs::SetBool::Request& request,
                          std_srvs::SetBool::Response& response) {
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    paused_ = request.data;
    ReanchorLocked();
  }
  wake_.notify_all();
  response.success = true;
  response.message = request.data ? "paused" : "running";
  return true;
}

bool SimNode::OnStep(rigid_body_sim::Step::Request& request,
                     rigid_body_sim::Step::Response& response) {
  Outbox outbox;
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    if (!paused_) {
      response.sim_time = world_.time();
      return Fail(response, "step is only allowed while paused; call ~set_paused with true first",
                  names::kStepService);
    }
    for (std::uint32_t i = 0; i < request.steps; ++i) StepLocked();
    ReanchorLocked();
    FillPeriodicLocked(&outbox);
    response.sim_time = world_.time();
  }
  Publish(std::move(outbox));
  response.success = true;
  response.message = "advanced " + std::to_string(request.steps) + " steps";
  return true;
}

bool SimNode::OnGetState(rigid_body_sim::GetState::Request& request,
                         rigid_body_sim::GetState::Response& response) {
  std::unique_lock<std::mutex> lock = LockWorld();
  Result<FrameRef> frame = registry_.ResolveFrame(request.name);
  if (!frame.ok()) return Fail(response, frame.message(), names::kGetStateService);
  const FrameState state =
      LinkStateFromRoot(RootStateLocked(*frame->model), frame->link->root_from_link);
  response.success = true;
  response.pose = PoseToMsg(state.world_from_frame);
  response.twist = TwistToMsg(state.linear_velocity, state.angular_velocity);
  return true;
}

bool SimNode::OnSetState(rigid_body_sim::SetState::Request& request,
                         rigid_body_sim::SetState::Response& response) {
  Result<FrameState> link_state = FrameStateFromMsg(request.pose, request.twist);
  if (!link_state.ok()) return Fail(response, link_state.message(), names::kSetStateService);
  Outbox outbox;
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    Result<FrameRef> frame = registry_.ResolveFrame(request.name);
    if (!frame.ok()) return Fail(response, frame.message(), names::kSetStateService);
    FrameState root = RootStateFromLink(*link_state, frame->link->root_from_link);
    if (frame->model->is_static) {
      root.linear_velocity.setZero();
      root.angular_velocity.setZero();
    }
    const Status status = world_.SetState(frame->model->body, root.world_from_frame,
                                          root.linear_velocity, root.angular_velocity);
    if (!status.ok()) return Fail(response, status.message(), names::kSetStateService);
    if (frame->model->is_static) outbox.tf_static = StaticTfLocked();
  }
  Publish(std::move(outbox));
  response.success = true;
  response.message = "moved '" + request.name + "'";
  return true;
}

bool SimNode::OnApplyWrench(rigid_body_sim::ApplyWrench::Request& request,
                            rigid_body_sim::ApplyWrench::Response& response) {
  const char* service = names::kApplyWrenchService;
  Result<Vec3> point = PointFromMsg(request.point, "point");
  if (!point.ok()) return Fail(response, point.message(), service);
  Result<Vec3> force = VectorFromMsg(request.wrench.force, "wrench.force");
  if (!force.ok()) return Fail(response, force.message(), service);
  Result<Vec3> torque = VectorFromMsg(request.wrench.torque, "wrench.torque");
  if (!torque.ok()) return Fail(response, torque.message(), service);
  if (!(request.duration >= 0.0) || !std::isfinite(request.duration)) {
    return Fail(response, "duration " + FormatNumber(request.duration) + " s must be >= 0 and finite",
                service);
  }
  std::unique_lock<std::mutex> lock = LockWorld();
  Result<FrameRef> frame = registry_.ResolveFrame(request.name);
  if (!frame.ok()) return Fail(response, frame.message(), service);
  if (frame->model->is_static) {
    return Fail(response, "model '" + frame->model->name + "' is static", service);
  }
  // The wrench acts for the steps that cover `duration` at the current time
  // step, at least one.
  const std::int64_t steps =
      std::max<std::int64_t>(1, std::llround(request.duration / world_.settings().time_step));
  wrenches_.push_back(ActiveWrench{frame->model->body, *force, *point, *torque, steps});
  response.success = true;
  response.message = "wrench on '" + request.name + "' for " + std::to_string(steps) + " steps";
  return true;
}

bool SimNode::OnGetPhysics(rigid_body_sim::GetPhysics::Request& /*request*/,
                           rigid_body_sim::GetPhysics::Response& response) {
  std::unique_lock<std::mutex> lock = LockWorld();
  response.gravity = VectorToMsg(world_.settings().gravity);
  response.time_step = world_.settings().time_step;
  response.real_time_factor = real_time_factor_;
  return true;
}

bool SimNode::OnSetPhysics(rigid_body_sim::SetPhysics::Request& request,
                           rigid_body_sim::SetPhysics::Response& response) {
  const char* service = names::kSetPhysicsService;
  Result<Vec3> gravity = VectorFromMsg(request.gravity, "gravity");
  if (!gravity.ok()) return Fail(response, gravity.message(), service);
  if (!(request.time_step > 0.0) || !std::isfinite(request.time_step)) {
    return Fail(response, "time_step " + FormatNumber(request.time_step) + " s must be positive",
                service);
  }
  if (!(request.real_time_factor >= 0.0) || !std::isfinite(request.real_time_factor)) {
    return Fail(response,
                "real_time_factor " + FormatNumber(request.real_time_factor) +
                    " must be >= 0 (0: as fast as possible)",
                service);
  }
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    physics::WorldSettings settings = world_.settings();
    settings.gravity = *gravity;
    settings.time_step = request.time_step;
    if (Status status = world_.SetSettings(settings); !status.ok()) {
      return Fail(response, status.message(), service);
    }
    real_time_factor_ = request.real_time_factor;
    ReanchorLocked();
  }
  wake_.notify_all();
  response.success = true;
  response.message = "physics set";
  return true;
}

void SimNode::OnBodyMarkersSubscriber(const ros::SingleSubscriberPublisher& publisher) {
  visualization_msgs::MarkerArray array;
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    for (const auto& [name, markers] : body_markers_) {
      array.markers.insert(array.markers.end(), markers.begin(), markers.end());
    }
  }
  publisher.publish(array);
}

// --- stepping -----------------------------------------------------------------

void SimNode::StepLocked() {
  for (ActiveWrench& wrench : wrenches_) {
    Status status = world_.ApplyForceAtPoint(wrench.body, wrench.force_world, wrench.point_world);
    assert(status.ok());
    status = world_.ApplyTorque(wrench.body, wrench.torque_world);
    assert(status.ok());
    --wrench.remaining_steps;
  }
  wrenches_.erase(std::remove_if(wrenches_.begin(), wrenches_.end(),
                                 [](const ActiveWrench& w) { return w.remaining_steps <= 0; }),
                  wrenches_.end());
  world_.Step();
  ++steps_;
}

void SimNode::ReanchorLocked() {
  anchor_wall_ = Clock::now();
  anchor_sim_ = world_.time();
}

void SimNode::StepLoop() {
  const auto publish_period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / options_.publish_rate));
  const auto clock_period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(kClockPeriodSeconds));
  const auto status_period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(options_.status_period));
  Clock::time_point next_publish = Clock::now();
  Clock::time_point next_clock = Clock::now();
  Clock::time_point next_status = Clock::now() + status_period;
  for (;;) {
    Outbox outbox;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (shutdown_) return;
      if (paused_) {
        wake_.wait_until(lock, next_publish, [this] { return shutdown_ || !paused_; });
        if (shutdown_) return;
      } else if (real_time_factor_ > 0.0) {
        // Real-time pacing: the next step is due when the wall clock has
        // caught up with sim time / real_time_factor.
        const auto due = anchor_wall_ +
                         std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                             (world_.time() - anchor_sim_) / real_time_factor_));
        if (Clock::now() < due) {
          const auto wake_at = std::min(due, next_publish);
          const auto anchor = anchor_wall_;
          wake_.wait_until(lock, wake_at,
                           [&] { return shutdown_ || paused_ || anchor_wall_ != anchor; });
          if (shutdown_) return;
        } else if (Clock::now() - due > std::chrono::duration<double>(kMaxLagSeconds)) {
          ReanchorLocked();
        }
        if (!paused_ && Clock::now() >= due) StepLocked();
      } else {
        StepLocked();
      }
      const Clock::time_point now = Clock::now();
      if (now >= next_publish) {
        FillPeriodicLocked(&outbox);
        next_publish = std::max(next_publish + publish_period, now);
      } else if (options_.use_sim_time && now >= next_clock && world_.time() > 0.0) {
        outbox.clock = world_.time();
      }
      if (outbox.clock) next_clock = now + clock_period;
      if (now >= next_status) {
        LogStatusLocked(now);
        next_status = now + status_period;
      }
    }
    Publish(std::move(outbox));
    // Service callers waiting for the mutex go first, so a flat-out loop
    // cannot starve them.
    while (waiting_.load(std::memory_order_acquire) > 0) std::this_thread::yield();
  }
}

FrameState SimNode::RootStateLocked(const Model& model) const {
  return FrameState{world_.GetPose(model.body), world_.GetLinearVelocity(model.body),
                    world_.GetAngularVelocity(model.body)};
}

tf2_msgs::TFMessage SimNode::ModelTfLocked(const Model& model) const {
  tf2_msgs::TFMessage tf;
  const FrameState root = RootStateLocked(model);
  const ros::Time stamp = SimTimeToRos(world_.time());
  for (const io::LinkFrame& link : model.links) {
    tf.transforms.push_back(TransformToMsg(root.world_from_frame * link.root_from_link,
                                           options_.world_frame,
                                           FrameName(model.name, link.link_name), stamp));
  }
  return tf;
}

tf2_msgs::TFMessage SimNode::StaticTfLocked() const {
  tf2_msgs::TFMessage tf;
  for (const auto& [name, model] : registry_.models()) {
    if (!model.is_static) continue;
    tf2_msgs::TFMessage model_tf = ModelTfLocked(model);
    tf.transforms.insert(tf.transforms.end(), model_tf.transforms.begin(),
                         model_tf.transforms.end());
  }
  return tf;
}

void SimNode::FillPeriodicLocked(Outbox* outbox) {
  outbox->reset_count = reset_count_;
  const double sim_time = world_.time();
  const ros::Time stamp = SimTimeToRos(sim_time);

  rigid_body_sim::ModelStates& states = outbox->states.emplace();
  states.header.stamp = stamp;
  states.header.frame_id = options_.world_frame;
  states.name.reserve(registry_.size());
  for (const auto& [name, model] : registry_.models()) {
    const FrameState root = RootStateLocked(model);
    for (const io::LinkFrame& link : model.links) {
      const FrameState state = LinkStateFromRoot(root, link.root_from_link);
      states.name.push_back(FrameName(name, link.link_name));
      states.pose.push_back(PoseToMsg(state.world_from_frame));
      states.twist.push_back(TwistToMsg(state.linear_velocity, state.angular_velocity));
    }
  }
  // tf2 drops a transform whose stamp it already holds, so tf and contacts
  // go out only when sim time moved.
  if (sim_time == last_periodic_time_) return;
  last_periodic_time_ = sim_time;

  tf2_msgs::TFMessage& tf = outbox->tf.emplace();
  tf.transforms.reserve(states.name.size());
  for (const auto& [name, model] : registry_.models()) {
    if (model.is_static) continue;
    const FrameState root = RootStateLocked(model);
    for (const io::LinkFrame& link : model.links) {
      tf.transforms.push_back(TransformToMsg(root.world_from_frame * link.root_from_link,
                                             options_.world_frame, FrameName(name, link.link_name),
                                             stamp));
    }
  }

  // Every colliding contact since the last message, and the resting and
  // separating contacts of the last step (its colliding ones are in the log).
  std::vector<physics::ContactReport> contacts = world_.TakeCollisionLog();
  for (const physics::ContactReport& contact : world_.contacts()) {
    if (contact.type != physics::ContactType::kColliding) contacts.push_back(contact);
  }
  const auto body_name = [this](BodyId body, int shape) {
    if (ground_ && body == *ground_) return std::string(names::kGroundName);
    return registry_.ShapeFrame(body, shape);
  };
  rigid_body_sim::Contacts& contacts_msg = outbox->contacts.emplace();
  contacts_msg.header.stamp = stamp;
  contacts_msg.header.frame_id = options_.world_frame;
  contacts_msg.contacts.reserve(contacts.size());
  for (const physics::ContactReport& contact : contacts) {
    contacts_msg.contacts.push_back(ContactToMsg(contact,
                                                 body_name(contact.body_a, contact.shape_a),
                                                 body_name(contact.body_b, contact.shape_b)));
  }
  ContactMarkerStyle style;
  style.frame = options_.world_frame;
  style.stamp = stamp;
  style.force_scale = options_.contact_force_scale;
  outbox->contact_markers = ContactMarkers(contacts, contact_marker_count_, style);
  contact_marker_count_ = static_cast<int>(contacts.size());
  if (options_.use_sim_time && sim_time > 0.0) outbox->clock = sim_time;
}

void SimNode::LogStatusLocked(Clock::time_point now) {
  const double wall = std::chrono::duration<double>(now - status_wall_).count();
  const double achieved = wall > 0.0 ? (world_.time() - status_sim_) / wall : 0.0;
  std::size_t static_models = 0;
  for (const auto& [name, model] : registry_.models()) static_models += model.is_static ? 1 : 0;
  const std::size_t awake = world_.AwakeBodyCount();
  const std::size_t dynamic = registry_.size() - static_models;
  ROS_INFO(
      "sim time %.3f s, real-time factor %.2f%s, bodies %zu (%zu awake, %zu asleep, %zu static), "
      "contacts %zu",
      world_.time(), achieved, paused_ ? " (paused)" : "", registry_.size(), awake,
      dynamic - std::min(awake, dynamic), static_models, world_.contacts().size());
  status_wall_ = now;
  status_sim_ = world_.time();
}

void SimNode::Publish(Outbox outbox) {
  if (outbox.tf_static) tf_static_publisher_.publish(*outbox.tf_static);
  if (outbox.tf && !outbox.tf->transforms.empty()) {
    // A snapshot built before a step service's one may reach here after it;
    // listeners would take the older poses as the latest, so it is dropped.
    std::lock_guard<std::mutex> lock(publish_mutex_);
    if (outbox.reset_count > tf_reset_count_) {
      tf_reset_count_ = outbox.reset_count;
      last_tf_stamp_ = ros::Time(0);
    }
    const ros::Time stamp = outbox.tf->transforms.front().header.stamp;
    if (outbox.reset_count == tf_reset_count_ &&
        (outbox.tf_is_new_frame || stamp >= last_tf_stamp_)) {
      tf_publisher_.publish(*outbox.tf);
      if (!outbox.tf_is_new_frame) last_tf_stamp_ = stamp;
    }
  }
  if (outbox.states) states_publisher_.publish(*outbox.states);
  if (outbox.contacts) contacts_publisher_.publish(*outbox.contacts);
  if (outbox.contact_markers && !outbox.contact_markers->markers.empty()) {
    contact_markers_publisher_.publish(*outbox.contact_markers);
  }
  if (outbox.body_markers) body_markers_publisher_.publish(*outbox.body_markers);
  if (outbox.clock && options_.use_sim_time) {
    std::lock_guard<std::mutex> lock(clock_mutex_);
    if (*outbox.clock > last_clock_) {
      rosgraph_msgs::Clock clock;
      clock.clock = SimTimeToRos(*outbox.clock);
      clock_publisher_.publish(clock);
      last_clock_ = *outbox.clock;
    }
  }
}

}  // namespace rigid_body_sim::node
