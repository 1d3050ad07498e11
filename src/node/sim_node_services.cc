// The node's services: each validates its request, then changes the world
// under its lock, or changes nothing and says why.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>

#include "rigid_body_sim/node/msg_conversion.h"
#include "rigid_body_sim/node/names.h"
#include "rigid_body_sim/node/sim_node.h"

namespace rigid_body_sim::node {

using physics::BodyId;
using physics::FormatNumber;
using physics::Result;
using physics::Status;
using physics::Vec3;

namespace {

template <typename Response>
bool Fail(Response& response, const std::string& message, const char* service) {
  response.success = false;
  response.message = message;
  ROS_WARN("~%s refused: %s", service, message.c_str());
  return true;
}

}  // namespace

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
    return Fail(response,
                "duration " + FormatNumber(request.duration) + " s must be >= 0 and finite",
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
  visualization_msgs::MarkerArray array;
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    for (const auto& [name, markers] : body_markers_) {
      array.markers.insert(array.markers.end(), markers.begin(), markers.end());
    }
  }
  publisher.publish(array);
}

}  // namespace rigid_body_sim::node
