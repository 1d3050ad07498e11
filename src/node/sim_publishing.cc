// What the node publishes: tf, model states, contacts and their markers, and
// /clock, built under the world lock and sent after it is released.
#include <algorithm>
#include <cassert>
#include <chrono>
#include <string>
#include <vector>

#include <rosgraph_msgs/Clock.h>

#include "node/model_sensors.h"
#include "rigid_body_sim/node/msg_conversion.h"
#include "rigid_body_sim/node/names.h"
#include "rigid_body_sim/node/sim_node.h"

namespace rigid_body_sim::node {

using physics::BodyId;

FrameState SimNode::LinkStateLocked(const Model& model, std::size_t link) const {
  const BodyId body = model.bodies[model.link_body[link]];
  const FrameState body_state{world_.GetPose(body), world_.GetLinearVelocity(body),
                              world_.GetAngularVelocity(body)};
  return LinkStateFromRoot(body_state, model.body_from_link[link]);
}

ros::Time SimNode::StampLocked() const {
  return options_.use_sim_time ? SimTimeToRos(world_.time()) : ros::Time::now();
}

namespace {

// A joint's link: every joint names links of its model.
std::size_t JointLink(const Model& model, const std::string& link_name) {
  const int index = LinkIndex(model, link_name);
  assert(index >= 0 && "a joint names a link of its model");
  return static_cast<std::size_t>(index);
}

}  // namespace

// A rigid model: every link frame from the world frame. An articulated one
// follows the URDF tree: the world to its root link, then each movable
// joint's parent link to its child link (its fixed joints are static). In
// TfMode::kRoot only the world to the root link, in kNone nothing.
void SimNode::AppendModelTfLocked(const Model& model, const ros::Time& stamp,
                                  tf2_msgs::TFMessage* tf) const {
  if (model.tf_mode == TfMode::kNone) return;
  const auto from_world = [&](std::size_t link) {
    tf->transforms.push_back(TransformToMsg(LinkStateLocked(model, link).world_from_frame,
                                            options_.world_frame,
                                            TfFrame(model, model.links[link].link_name), stamp));
  };
  if (model.tf_mode == TfMode::kRoot) {
    // A root fixed to the URDF's `world` link: robot_state_publisher
    // publishes world -> root from the URDF; a second parent would split
    // the tree.
    if (const RunningDiffDrive* drive = RootTfDriveLocked(model); drive != nullptr) {
      AppendDriveTfLocked(model, *drive, stamp, tf);
    } else if (!model.world_link) {
      from_world(0);
    }
    return;
  }
  if (!model.articulation.IsValid()) {
    for (std::size_t i = 0; i < model.links.size(); ++i) from_world(i);
    return;
  }
  if (const RunningDiffDrive* drive = RootTfDriveLocked(model); drive != nullptr) {
    AppendDriveTfLocked(model, *drive, stamp, tf);
  } else {
    from_world(0);
  }
  for (const io::JointInfo& joint : model.joints) {
    if (joint.type == "fixed") continue;
    const physics::Pose world_from_parent =
        LinkStateLocked(model, JointLink(model, joint.parent_link)).world_from_frame;
    const physics::Pose world_from_child =
        LinkStateLocked(model, JointLink(model, joint.child_link)).world_from_frame;
    tf->transforms.push_back(TransformToMsg(world_from_parent.Inverse() * world_from_child,
                                            TfFrame(model, joint.parent_link),
                                            TfFrame(model, joint.child_link), stamp));
  }
}

tf2_msgs::TFMessage SimNode::ModelTfLocked(const Model& model) const {
  tf2_msgs::TFMessage tf;
  AppendModelTfLocked(model, StampLocked(), &tf);
  return tf;
}

// The frames of static models, and the fixed joints of articulated ones.
tf2_msgs::TFMessage SimNode::StaticTfLocked() const {
  tf2_msgs::TFMessage tf;
  const ros::Time stamp = StampLocked();
  for (const auto& [name, model] : registry_.models()) {
    if (model.is_static) AppendModelTfLocked(model, stamp, &tf);
    if (!model.articulation.IsValid() || model.tf_mode != TfMode::kLinks) continue;
    for (const io::JointInfo& joint : model.joints) {
      if (joint.type != "fixed") continue;
      const physics::Pose& root_from_parent =
          model.links[JointLink(model, joint.parent_link)].root_from_link;
      const physics::Pose& root_from_child =
          model.links[JointLink(model, joint.child_link)].root_from_link;
      tf.transforms.push_back(TransformToMsg(root_from_parent.Inverse() * root_from_child,
                                             TfFrame(model, joint.parent_link),
                                             TfFrame(model, joint.child_link), stamp));
    }
  }
  return tf;
}

void SimNode::FillTfLocked(const ros::Time& stamp, tf2_msgs::TFMessage* tf) const {
  for (const auto& [name, model] : registry_.models()) {
    if (!model.is_static) AppendModelTfLocked(model, stamp, tf);
  }
}

void SimNode::FillPeriodicLocked(Outbox* outbox) {
  outbox->reset_count = reset_count_;
  const double sim_time = world_.time();
  const ros::Time stamp = StampLocked();

  rigid_body_sim::ModelStates& states = outbox->states.emplace();
  states.header.stamp = stamp;
  states.header.frame_id = options_.world_frame;
  states.name.reserve(registry_.size());
  for (const auto& [name, model] : registry_.models()) {
    for (std::size_t i = 0; i < model.links.size(); ++i) {
      const FrameState state = LinkStateLocked(model, i);
      states.name.push_back(FrameName(name, model.links[i].link_name));
      states.pose.push_back(PoseToMsg(state.world_from_frame));
      states.twist.push_back(TwistToMsg(state.linear_velocity, state.angular_velocity));
    }
  }
  states.frozen.assign(frozen_models_.begin(), frozen_models_.end());
  FillJointStatesLocked(stamp, outbox);
  // tf2 drops a transform whose stamp it already holds, so under sim time
  // tf goes out only when sim time moved; contacts always only then.
  const bool sim_time_moved = sim_time != last_periodic_time_;
  if (sim_time_moved || !options_.use_sim_time) FillTfLocked(stamp, &outbox->tf.emplace());
  if (!sim_time_moved) return;
  last_periodic_time_ = sim_time;

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

bool SimNode::FillPeriodicIfDueLocked(Clock::time_point now, Outbox* outbox) {
  if (now < next_publish_) return false;
  FillPeriodicLocked(outbox);
  const auto publish_period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / live_.publish_rate));
  next_publish_ = std::max(next_publish_ + publish_period, now);
  return true;
}

void SimNode::Publish(Outbox outbox) {
  if (outbox.tf_static) {
    std::lock_guard<std::mutex> lock(static_mutex_);
    // The new broadcaster is made before the old one goes, so the topic
    // stays advertised and its latched message is replaced, not dropped.
    static_broadcaster_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
    static_broadcaster_->sendTransform(outbox.tf_static->transforms);
  }
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
      tf_broadcaster_->sendTransform(outbox.tf->transforms);
      if (!outbox.tf_is_new_frame) last_tf_stamp_ = stamp;
    }
  }
  if (outbox.states) states_publisher_.publish(*outbox.states);
  PublishJointStates(outbox);
  if (outbox.contacts) contacts_publisher_.publish(*outbox.contacts);
  if (outbox.contact_markers && !outbox.contact_markers->markers.empty()) {
    contact_markers_publisher_.publish(*outbox.contact_markers);
  }
  if (outbox.body_markers) body_markers_publisher_.publish(*outbox.body_markers);
  for (const std::function<void()>& publish : outbox.sensors) publish();
  if (outbox.diagnostics) diagnostics_->Publish();
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
