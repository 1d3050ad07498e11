// The node's services: each validates its request, then changes the world
// under its lock, or changes nothing and says why.
#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdint>

#include "node/model_sensors.h"
#include "node/service_reply.h"
#include "rigid_body_sim/node/msg_conversion.h"
#include "rigid_body_sim/node/names.h"
#include "rigid_body_sim/node/request_validation.h"
#include "rigid_body_sim/node/sim_node.h"

namespace rigid_body_sim::node {

using physics::BodyId;
using physics::FormatNumber;
using physics::Result;
using physics::Status;
using physics::Vec3;

bool SimNode::OnSpawn(rigid_body_sim::Spawn::Request& request,
                      rigid_body_sim::Spawn::Response& response) {
  Result<ModelSpec> spec = ModelSpecFromMsg(request);
  if (!spec.ok()) return Fail(response, spec.message(), names::kSpawnService);
  if (Status status = ValidateModelSpec(*spec, options_.limits); !status.ok()) {
    return Fail(response, status.message(), names::kSpawnService);
  }
  Result<SpawnedModel> spawned = SpawnModel(*spec);
  if (!spawned.ok()) {
    return Fail(response, "cannot spawn '" + request.name + "': " + spawned.message(),
                names::kSpawnService);
  }
  response.success = true;
  response.message = "spawned '" + request.name + "'" + DescribeOverlaps(request.name);
  // Said once, in the reply: what the description asks for that does not
  // run here (a Gazebo user's controllers, plugins and sensors).
  std::string ignored;
  for (const std::string& element : spawned->ignored) {
    ignored += (ignored.empty() ? "; ignored (not simulated): " : ", ") + element;
  }
  response.message += ignored;
  response.frames = spawned->frames;
  return true;
}

// "; overlaps 'crate' by 0.1 m, 'ground' by 0.05 m" for what the model
// was spawned into, deepest first; the step pushes them apart by positions
// only, so nothing is launched.
std::string SimNode::DescribeOverlaps(const std::string& model_name) {
  std::unique_lock<std::mutex> lock = LockWorld();
  const Model* model = registry_.Find(model_name);
  if (model == nullptr) return "";
  std::string text;
  for (const physics::BodyOverlap& overlap : world_.FindOverlaps(model->body)) {
    const Model* other = registry_.FindByBody(overlap.other);
    const std::string name = other != nullptr ? other->name : names::kGroundName;
    text += (text.empty() ? "; overlaps '" : ", '") + name + "' by " + FormatNumber(overlap.depth) +
            " m";
  }
  if (!text.empty())
    ROS_WARN("model '%s' spawned into an overlap%s", model_name.c_str(), text.c_str());
  return text;
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
    const std::vector<BodyId> bodies = model->bodies;
    const bool was_static = model->is_static || model->articulation.IsValid();
    const Status destroyed = model->articulation.IsValid()
                                 ? world_.DestroyArticulation(model->articulation)
                                 : world_.DestroyBody(model->body);
    assert(destroyed.ok());
    const auto on_model = [&bodies](const ActiveWrench& w) {
      return std::find(bodies.begin(), bodies.end(), w.body) != bodies.end();
    };
    wrenches_.erase(std::remove_if(wrenches_.begin(), wrenches_.end(), on_model), wrenches_.end());
    if (model->articulation.IsValid()) RemoveJointTopics(request.name);
    // Its cmd_vel callback takes no world lock, so its subscriber may go
    // under it.
    sensors_.erase(request.name);
    registry_.Remove(request.name);
    frozen_models_.erase(request.name);
    const auto found = body_markers_.find(request.name);
    const int marker_count =
        found != body_markers_.end() ? static_cast<int>(found->second->size()) : 0;
    if (found != body_markers_.end()) body_markers_.erase(found);
    outbox.body_markers.emplace().markers = DeleteMarkers(request.name, marker_count);
    if (was_static) outbox.tf_static = StaticTfLocked();
  }
  DestroyRetiredJointTopics();
  Publish(std::move(outbox));
  response.success = true;
  response.message = "deleted '" + request.name + "'";
  return true;
}

bool SimNode::OnSetPaused(std_srvs::SetBool::Request& request,
                          std_srvs::SetBool::Response& response) {
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    paused_ = request.data;
    ReanchorLocked();
    if (step_in_progress_) cancel_step_ = names::kSetPausedService;
  }
  wake_.notify_all();
  response.success = true;
  response.message = request.data ? "paused" : "running";
  return true;
}

namespace {

// A long ~step call holds the world for at most this long at a time, so that
// other services answer and the loop publishes between its chunks.
constexpr std::chrono::milliseconds kStepChunk(10);

}  // namespace

bool SimNode::OnStep(rigid_body_sim::Step::Request& request,
                     rigid_body_sim::Step::Response& response) {
  const char* service = names::kStepService;
  if (Status status = ValidateStepCount(request.steps, options_.limits); !status.ok()) {
    return Fail(response, status.message(), service);
  }
  std::lock_guard<std::mutex> one_call(step_service_mutex_);
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    response.sim_time = world_.time();
    if (!paused_) {
      return Fail(response, "step is only allowed while paused; call ~set_paused with true first",
                  service);
    }
    step_in_progress_ = true;
    cancel_step_.clear();
  }
  // Whatever ends the call, even an exception, ends the step in progress.
  struct StepCallEnd {
    SimNode* node;
    ~StepCallEnd() {
      std::unique_lock<std::mutex> lock = node->LockWorld();
      node->step_in_progress_ = false;
    }
  } step_call_end{this};
  std::uint32_t done = 0;
  std::string stopped_by;
  while (stopped_by.empty()) {
    Outbox outbox;
    {
      std::unique_lock<std::mutex> lock = LockWorld();
      if (!cancel_step_.empty()) {
        stopped_by = cancel_step_;
      } else if (!paused_) {
        stopped_by = names::kSetPausedService;
      } else {
        const auto chunk_end = Clock::now() + kStepChunk;
        while (done < request.steps && Clock::now() < chunk_end) {
          StepLocked();
          ++done;
        }
        ReanchorLocked();
        if (done == request.steps) stopped_by = "done";
      }
      // The call publishes at ~publish_rate itself: between its chunks the
      // step loop's thread may not win the world's lock.
      if (!stopped_by.empty()) {
        FillPeriodicLocked(&outbox);
      } else {
        FillPeriodicIfDueLocked(Clock::now(), &outbox);
      }
      response.sim_time = world_.time();
      outbox.sensors.swap(pending_sensor_messages_);
    }
    Publish(std::move(outbox));
    // Callers waiting for the world go first, as in the step loop.
    while (waiting_.load(std::memory_order_acquire) > 0) std::this_thread::yield();
  }
  if (stopped_by != "done") {
    return Fail(response,
                "stopped by ~" + stopped_by + " after " + std::to_string(done) + " of " +
                    std::to_string(request.steps) + " steps",
                service);
  }
  response.success = true;
  response.message = "advanced " + std::to_string(done) + " steps";
  return true;
}

bool SimNode::OnCancelStep(std_srvs::Trigger::Request& /*request*/,
                           std_srvs::Trigger::Response& response) {
  std::unique_lock<std::mutex> lock = LockWorld();
  if (!step_in_progress_) {
    response.success = false;
    response.message = "no ~step call in progress";
    return true;
  }
  cancel_step_ = names::kCancelStepService;
  response.success = true;
  response.message = "the ~step call in progress stops after its current chunk";
  return true;
}

bool SimNode::OnGetState(rigid_body_sim::GetState::Request& request,
                         rigid_body_sim::GetState::Response& response) {
  std::unique_lock<std::mutex> lock = LockWorld();
  Result<FrameRef> frame = registry_.ResolveFrame(request.name);
  if (!frame.ok()) return Fail(response, frame.message(), names::kGetStateService);
  const FrameState state = LinkStateLocked(
      *frame->model, static_cast<std::size_t>(frame->link - frame->model->links.data()));
  response.success = true;
  if (frozen_models_.count(frame->model->name) != 0) {
    response.message =
        "frozen: its state stopped being finite; held at its last finite pose "
        "until ~set_state or ~reset";
  }
  response.pose = PoseToMsg(state.world_from_frame);
  response.twist = TwistToMsg(state.linear_velocity, state.angular_velocity);
  return true;
}

bool SimNode::OnSetState(rigid_body_sim::SetState::Request& request,
                         rigid_body_sim::SetState::Response& response) {
  Result<FrameState> link_state = FrameStateFromMsg(request.pose, request.twist);
  if (!link_state.ok()) return Fail(response, link_state.message(), names::kSetStateService);
  if (Status status = ValidateFrameState(*link_state, options_.limits); !status.ok()) {
    return Fail(response, status.message(), names::kSetStateService);
  }
  Outbox outbox;
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    Result<FrameRef> frame = registry_.ResolveFrame(request.name);
    if (!frame.ok()) return Fail(response, frame.message(), names::kSetStateService);
    // The body that carries the link takes the state that puts the link
    // where asked; an articulated model moves rigidly with it.
    const Model& model = *frame->model;
    const std::size_t link = static_cast<std::size_t>(frame->link - model.links.data());
    FrameState root = RootStateFromLink(*link_state, model.body_from_link[link]);
    if (model.is_static) {
      root.linear_velocity.setZero();
      root.angular_velocity.setZero();
    }
    const Status status =
        world_.SetState(model.bodies[model.link_body[link]], root.world_from_frame,
                        root.linear_velocity, root.angular_velocity);
    if (!status.ok()) return Fail(response, status.message(), names::kSetStateService);
    frozen_models_.erase(frame->model->name);
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
  if (Status status = ValidateWrench(*force, *torque, *point, request.duration, options_.limits);
      !status.ok()) {
    return Fail(response, status.message(), service);
  }
  std::unique_lock<std::mutex> lock = LockWorld();
  Result<FrameRef> frame = registry_.ResolveFrame(request.name);
  if (!frame.ok()) return Fail(response, frame.message(), service);
  if (frame->model->is_static) {
    return Fail(response, "model '" + frame->model->name + "' is static", service);
  }
  // The wrench acts for the steps that cover `duration` at the current time
  // step, at least one.
  const std::int64_t steps = WrenchSteps(request.duration, world_.settings().time_step);
  const std::size_t link = static_cast<std::size_t>(frame->link - frame->model->links.data());
  const BodyId body = frame->model->bodies[frame->model->link_body[link]];
  wrenches_.push_back(ActiveWrench{body, *force, *point, *torque, steps});
  response.success = true;
  response.message = "wrench on '" + request.name + "' for " + std::to_string(steps) + " steps";
  return true;
}

bool SimNode::OnGetPhysics(rigid_body_sim::GetPhysics::Request& /*request*/,
                           rigid_body_sim::GetPhysics::Response& response) {
  std::unique_lock<std::mutex> lock = LockWorld();
  response.gravity = VectorToMsg(live_.gravity);
  response.time_step = live_.time_step;
  response.real_time_factor = live_.real_time_factor;
  return true;
}

bool SimNode::OnSetPhysics(rigid_body_sim::SetPhysics::Request& request,
                           rigid_body_sim::SetPhysics::Response& response) {
  const char* service = names::kSetPhysicsService;
  Result<Vec3> gravity = VectorFromMsg(request.gravity, "gravity");
  if (!request.keep_gravity && !gravity.ok()) return Fail(response, gravity.message(), service);
  std::vector<std::string> warnings;
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    LiveSettings settings = live_;
    if (!request.keep_gravity) settings.gravity = *gravity;
    if (request.time_step != 0.0) settings.time_step = request.time_step;
    if (!(request.real_time_factor < 0.0)) settings.real_time_factor = request.real_time_factor;
    if (Status status = ValidateLiveSettings(settings, ""); !status.ok()) {
      return Fail(response, status.message(), service);
    }
    if (Status status = ApplyLiveSettingsLocked(settings); !status.ok()) {
      return Fail(response, status.message(), service);
    }
    warnings = LiveSettingsWarnings(settings, "");
  }
  wake_.notify_all();
  PushReconfigureConfig();
  response.success = true;
  response.message = "physics set";
  for (const std::string& warning : warnings) {
    ROS_WARN("~%s: %s", service, warning.c_str());
    response.message += "; warning: " + warning;
  }
  return true;
}

void SimNode::OnBodyMarkersSubscriber(const ros::SingleSubscriberPublisher& publisher) {
  try {
    std::vector<MarkerList> lists;
    {
      std::unique_lock<std::mutex> lock = LockWorld();
      for (const auto& [name, markers] : body_markers_) lists.push_back(markers);
    }
    visualization_msgs::MarkerArray array;
    for (const MarkerList& markers : lists) {
      array.markers.insert(array.markers.end(), markers->begin(), markers->end());
    }
    publisher.publish(array);
  } catch (const std::exception& error) {
    ROS_ERROR("~%s subscriber: %s", names::kBodyMarkersTopic, error.what());
  }
}

}  // namespace rigid_body_sim::node
