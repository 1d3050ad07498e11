// Articulations in the world: creation with its checks, joint state and
// commands, and moving a whole articulation when one of its links is set.
#include "physics/articulation/articulation_system.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "physics/dynamics/body_state.h"

namespace rigid_body_sim::physics {
namespace {

constexpr std::size_t kMaxLinks = 1000;

std::string JointField(std::size_t joint, const std::string& name, const std::string& field) {
  return "joint " + std::to_string(joint) + " ('" + name + "') " + field;
}

Status ValidateJoint(const ArticulationDef& def, std::size_t k) {
  const JointDef& joint = def.joints[k];
  if (joint.child_link != static_cast<int>(k) + 1 || joint.parent_link < 0 ||
      joint.parent_link > static_cast<int>(k)) {
    return Status::Error(JointField(
        k, joint.name,
        "must join link " + std::to_string(k + 1) + " to an earlier link; joins " +
            std::to_string(joint.parent_link) + " to " + std::to_string(joint.child_link)));
  }
  if (!IsFinite(joint.axis) || !(joint.axis.norm() > 1e-9)) {
    return Status::Error(JointField(k, joint.name, "axis must be finite and non-zero"));
  }
  if (!IsFinite(joint.parent_from_joint.translation) ||
      !IsFinite(joint.parent_from_joint.rotation) ||
      std::abs(joint.parent_from_joint.rotation.norm() - 1.0) > 1e-6) {
    return Status::Error(JointField(k, joint.name, "origin must be finite with a unit quaternion"));
  }
  const bool limited = joint.type != JointType::kContinuous;
  if (limited &&
      (std::isnan(joint.lower) || std::isnan(joint.upper) || joint.lower > joint.upper)) {
    return Status::Error(JointField(k, joint.name,
                                    "limits [" + FormatNumber(joint.lower) + ", " +
                                        FormatNumber(joint.upper) + "] must have lower <= upper"));
  }
  if (!(joint.effort_limit > 0.0) || !(joint.velocity_limit > 0.0)) {
    return Status::Error(JointField(k, joint.name,
                                    "effort and velocity limits must be > 0; got " +
                                        FormatNumber(joint.effort_limit) + " and " +
                                        FormatNumber(joint.velocity_limit)));
  }
  if (!(joint.damping >= 0.0) || !std::isfinite(joint.damping) || !(joint.friction >= 0.0) ||
      !std::isfinite(joint.friction)) {
    return Status::Error(JointField(k, joint.name,
                                    "damping " + FormatNumber(joint.damping) + " and friction " +
                                        FormatNumber(joint.friction) + " must be finite and >= 0"));
  }
  if (joint.mimic_joint >= 0) {
    if (joint.mimic_joint >= static_cast<int>(def.joints.size()) ||
        joint.mimic_joint == static_cast<int>(k) ||
        def.joints[joint.mimic_joint].mimic_joint >= 0 || !std::isfinite(joint.mimic_multiplier) ||
        !std::isfinite(joint.mimic_offset)) {
      return Status::Error(JointField(
          k, joint.name, "must mimic another joint that mimics none, with finite factors"));
    }
    return Status::Ok();
  }
  if (!std::isfinite(joint.position) || !std::isfinite(joint.velocity)) {
    return Status::Error(JointField(k, joint.name, "position and velocity must be finite"));
  }
  if (limited && (joint.position < joint.lower || joint.position > joint.upper)) {
    return Status::Error(JointField(k, joint.name,
                                    "position " + FormatNumber(joint.position) +
                                        " is outside its limits [" + FormatNumber(joint.lower) +
                                        ", " + FormatNumber(joint.upper) + "]"));
  }
  return Status::Ok();
}

Status ValidateArticulation(const ArticulationDef& def) {
  if (def.links.empty() || def.links.size() > kMaxLinks) {
    return Status::Error("an articulation needs 1 to " + std::to_string(kMaxLinks) +
                         " links, got " + std::to_string(def.links.size()));
  }
  if (def.joints.size() + 1 != def.links.size()) {
    return Status::Error("an articulation of " + std::to_string(def.links.size()) +
                         " links needs " + std::to_string(def.links.size() - 1) + " joints, got " +
                         std::to_string(def.joints.size()));
  }
  for (std::size_t i = 0; i < def.links.size(); ++i) {
    if (Status status = ValidateMassProperties(def.links[i].mass_properties); !status.ok()) {
      return Status::Error("link " + std::to_string(i) + " ('" + def.links[i].name +
                           "'): " + status.message());
    }
  }
  for (std::size_t k = 0; k < def.joints.size(); ++k) {
    if (Status status = ValidateJoint(def, k); !status.ok()) return status;
  }
  return Status::Ok();
}

ArticulationModel MakeModel(const ArticulationDef& def) {
  ArticulationModel model;
  model.fixed_base = def.fixed_base;
  model.self_collide = def.self_collide;
  model.base_dofs = def.fixed_base ? 0 : 6;
  for (const LinkDef& link_def : def.links) {
    ArticulationLink& link = model.links.emplace_back();
    link.mass = link_def.mass_properties.mass;
    link.com_link = link_def.mass_properties.center_of_mass;
    link.inertia_link = link_def.mass_properties.inertia_about_com;
  }
  for (const JointDef& joint_def : def.joints) {
    ArticulationJoint& joint = model.joints.emplace_back();
    joint.def = joint_def;
    joint.def.axis.normalize();
    if (joint_def.type == JointType::kContinuous) {
      joint.def.lower = -std::numeric_limits<double>::infinity();
      joint.def.upper = std::numeric_limits<double>::infinity();
    }
    if (joint_def.mimic_joint < 0) joint.dof = model.joint_dofs++;
    model.links[joint_def.child_link].parent_joint = static_cast<int>(model.joints.size()) - 1;
  }
  for (const ArticulationJoint& joint : model.joints) {
    if (joint.dof >= 0) continue;
    model.joints[joint.def.mimic_joint].effort_scale +=
        joint.def.mimic_multiplier * joint.def.mimic_multiplier;
  }
  return model;
}

}  // namespace

ArticulationSystem::ArticulationSystem(std::vector<Body>* bodies, LinkBodies* world)
    : bodies_(*bodies), world_(*world) {}

Result<ArticulationId> ArticulationSystem::Create(const ArticulationDef& def) {
  if (Status status = ValidateArticulation(def); !status.ok()) return status;
  if (Status status =
          ValidateState(def.world_from_base, def.base_linear_velocity, def.base_angular_velocity);
      !status.ok()) {
    return Status::Error("base: " + status.message());
  }
  ArticulationEntry entry;
  entry.model = MakeModel(def);
  ArticulationState& state = entry.state;
  const ArticulationLink& base = entry.model.links[0];
  state.base_rotation = def.world_from_base.rotation.normalized();
  state.base_com = def.world_from_base * base.com_link;
  state.q.setZero(entry.model.joint_dofs);
  state.u.setZero(entry.model.DofCount());
  for (const ArticulationJoint& joint : entry.model.joints) {
    if (joint.dof < 0) continue;
    state.q[joint.dof] = joint.def.position;
    state.u[entry.model.base_dofs + joint.dof] = joint.def.velocity;
  }
  if (!def.fixed_base) {
    state.u.head<3>() =
        def.base_linear_velocity +
        def.base_angular_velocity.cross(state.base_com - def.world_from_base.translation);
    state.u.segment<3>(3) = def.base_angular_velocity;
  }
  entry.next = state;

  ArticulationKinematics k;
  ComputeKinematics(entry.model, state, &k, KinematicsParts::kPosesAndVelocities);
  std::uint32_t index = 0;
  while (index < articulations_.size() && articulations_[index].in_use) ++index;
  if (index == articulations_.size()) articulations_.emplace_back();
  for (std::size_t i = 0; i < def.links.size(); ++i) {
    BodyDef body_def;
    body_def.world_from_body = k.world_from_link[i];
    body_def.angular_velocity = k.angular_velocity[i];
    body_def.linear_velocity =
        k.linear_velocity[i] +
        k.angular_velocity[i].cross(k.world_from_link[i].translation - k.com_world[i]);
    body_def.mass_properties = def.links[i].mass_properties;
    body_def.shapes = def.links[i].shapes;
    body_def.user_data = def.user_data;
    Result<BodyId> body = world_.CreateBody(body_def);
    if (!body.ok()) {
      for (std::size_t made = 0; made < i; ++made)
        world_.DestroyBody(world_.BodyIdOf(entry.model.links[made].body));
      return Status::Error("link " + std::to_string(i) + " ('" + def.links[i].name +
                           "'): " + body.status().message());
    }
    entry.model.links[i].body = body.value().index;
    bodies_[body.value().index].articulation = static_cast<std::int32_t>(index);
    bodies_[body.value().index].link = static_cast<std::int32_t>(i);
  }
  entry.in_use = true;
  entry.generation = articulations_[index].generation;
  articulations_[index] = std::move(entry);
  return ArticulationId{index, articulations_[index].generation};
}

Status ArticulationSystem::Destroy(ArticulationId id) {
  if (!IsValid(id)) return Status::Error("no articulation with this id");
  ArticulationEntry& entry = articulations_[id.index];
  for (const ArticulationLink& link : entry.model.links) {
    bodies_[link.body].articulation = -1;
    world_.DestroyBody(world_.BodyIdOf(link.body));
  }
  const std::uint32_t next_generation = entry.generation + 1;
  entry = ArticulationEntry();
  entry.generation = next_generation;
  return Status::Ok();
}

bool ArticulationSystem::IsValid(ArticulationId id) const {
  return id.index < articulations_.size() && articulations_[id.index].in_use &&
         articulations_[id.index].generation == id.generation;
}

std::vector<BodyId> ArticulationSystem::Links(ArticulationId id) const {
  std::vector<BodyId> links;
  if (!IsValid(id)) return links;
  for (const ArticulationLink& link : articulations_[id.index].model.links) {
    links.push_back(world_.BodyIdOf(link.body));
  }
  return links;
}

std::vector<JointState> ArticulationSystem::GetJointStates(ArticulationId id) const {
  std::vector<JointState> states;
  if (!IsValid(id)) return states;
  const ArticulationEntry& entry = articulations_[id.index];
  for (std::size_t j = 0; j < entry.model.joints.size(); ++j) {
    JointState& state = states.emplace_back();
    state.position = JointPosition(entry.model, entry.state, static_cast<int>(j));
    state.velocity = JointVelocity(entry.model, entry.state, static_cast<int>(j));
    state.effort = entry.model.joints[j].effort;
  }
  return states;
}

// Positions and velocities of every joint, in joint order; a mimic joint's
// entries are ignored. A position that changes must lie within its limits.
Status ArticulationSystem::SetJointStates(ArticulationId id, const std::vector<double>& positions,
                                          const std::vector<double>& velocities) {
  if (!IsValid(id)) return Status::Error("no articulation with this id");
  ArticulationEntry& entry = articulations_[id.index];
  const std::size_t count = entry.model.joints.size();
  if (positions.size() != count || velocities.size() != count) {
    return Status::Error("joint state needs " + std::to_string(count) +
                         " positions and velocities, got " + std::to_string(positions.size()) +
                         " and " + std::to_string(velocities.size()));
  }
  ArticulationState state = entry.state;
  for (std::size_t j = 0; j < count; ++j) {
    const ArticulationJoint& joint = entry.model.joints[j];
    if (!std::isfinite(positions[j]) || !std::isfinite(velocities[j])) {
      return Status::Error(JointField(j, joint.def.name,
                                      "position " + FormatNumber(positions[j]) + " and velocity " +
                                          FormatNumber(velocities[j]) + " must be finite"));
    }
    if (joint.dof < 0) continue;
    // Contacts may have pushed a joint past its limit, where the limit row
    // is bringing it back: keeping that position is not setting one.
    const bool kept = positions[j] == state.q[joint.dof];
    if (!kept && (positions[j] < joint.def.lower || positions[j] > joint.def.upper)) {
      return Status::Error(JointField(
          j, joint.def.name,
          "position " + FormatNumber(positions[j]) + " is outside its limits [" +
              FormatNumber(joint.def.lower) + ", " + FormatNumber(joint.def.upper) + "]"));
    }
    state.q[joint.dof] = positions[j];
    state.u[entry.model.base_dofs + joint.dof] = velocities[j];
  }
  entry.state = state;
  entry.next = state;
  Teleported(&entry);
  PlaceLinks(id.index, /*restart=*/true);
  return Status::Ok();
}

Status ArticulationSystem::SetJointCommand(ArticulationId id, int joint,
                                           const JointCommand& command) {
  if (!IsValid(id)) return Status::Error("no articulation with this id");
  ArticulationEntry& entry = articulations_[id.index];
  if (joint < 0 || joint >= static_cast<int>(entry.model.joints.size())) {
    return Status::Error("joint index " + std::to_string(joint) + " is outside [0, " +
                         std::to_string(entry.model.joints.size()) + ")");
  }
  if (!std::isfinite(command.position) || !std::isfinite(command.velocity) ||
      !std::isfinite(command.effort)) {
    return Status::Error("joint command values must be finite");
  }
  if (!(command.max_effort >= 0.0)) {
    return Status::Error("joint command max_effort " + FormatNumber(command.max_effort) +
                         " is outside the allowed range [0, inf] N m or N");
  }
  ArticulationJoint& target = entry.model.joints[joint];
  if (target.dof < 0 && command.mode != JointCommandMode::kNone) {
    return Status::Error(
        JointField(joint, target.def.name, "mimics another joint; command its leader"));
  }
  target.command = command;
  return Status::Ok();
}

Status ArticulationSystem::SetServoGains(ArticulationId id, const ServoGains& gains) {
  if (!IsValid(id)) return Status::Error("no articulation with this id");
  if (!(gains.stiffness > 0.0) || !std::isfinite(gains.stiffness) || !(gains.damping >= 0.0) ||
      !std::isfinite(gains.damping)) {
    return Status::Error("servo stiffness " + FormatNumber(gains.stiffness) +
                         " must be finite and > 0, damping " + FormatNumber(gains.damping) +
                         " finite and >= 0");
  }
  articulations_[id.index].gains = gains;
  return Status::Ok();
}

// Setting one link's state moves the whole articulation rigidly with it:
// the base goes where it keeps its pose relative to that link, the joints
// keep their positions and stop, and a floating base takes the twist that
// gives the link the velocity asked for.
Status ArticulationSystem::MoveWithLink(std::uint32_t index, const Pose& world_from_link,
                                        const Vec3& linear_velocity, const Vec3& angular_velocity,
                                        int link) {
  ArticulationEntry& entry = articulations_[index];
  ArticulationKinematics k;
  ComputeKinematics(entry.model, entry.state, &k, KinematicsParts::kPosesAndVelocities);
  const Pose world_from_base =
      world_from_link * k.world_from_link[link].Inverse() * k.world_from_link[0];
  ArticulationState state = entry.state;
  state.base_rotation = world_from_base.rotation.normalized();
  state.base_com = world_from_base * entry.model.links[0].com_link;
  state.u.setZero();
  if (!entry.model.fixed_base) {
    state.u.head<3>() =
        linear_velocity + angular_velocity.cross(state.base_com - world_from_link.translation);
    state.u.segment<3>(3) = angular_velocity;
  }
  entry.state = state;
  entry.next = state;
  Teleported(&entry);
  PlaceLinks(index, /*restart=*/true);
  return Status::Ok();
}

// Puts every link body where the state says, with its velocity. A restart
// (a teleport) also forgets the links' contacts and wakes what touched them.
// A state set from outside starts the articulation over: its kinematics
// are stale, and the splits and joint-row impulses of the motion it left
// are not this one's, so that a reset replays its first run bit for bit.
void ArticulationSystem::Teleported(ArticulationEntry* entry) {
  entry->kinematics_current = false;
  entry->free_motion.Restart();
  std::fill(entry->joint_row_impulses.begin(), entry->joint_row_impulses.end(), 0.0);
}

void ArticulationSystem::PlaceLinks(std::uint32_t index, bool restart) {
  ArticulationEntry& entry = articulations_[index];
  if (!entry.kinematics_current) {
    ComputeKinematics(entry.model, entry.state, &entry.kinematics,
                      KinematicsParts::kPosesAndVelocities);
    entry.kinematics_current = true;
  }
  const ArticulationKinematics& k = entry.kinematics;
  for (std::size_t i = 0; i < entry.model.links.size(); ++i) {
    const std::uint32_t body_index = entry.model.links[i].body;
    Body& body = bodies_[body_index];
    const Vec3 start_com = body.position;
    const Quat start_rotation = body.orientation;
    const Vec3 origin_velocity =
        k.linear_velocity[i] +
        k.angular_velocity[i].cross(k.world_from_link[i].translation - k.com_world[i]);
    SetBodyState(k.world_from_link[i], origin_velocity, k.angular_velocity[i], &body);
    body.disabled = false;
    // The narrow phase skips pairs by how far their bodies travelled.
    body.travel += (body.position - start_com).norm() +
                   start_rotation.angularDistance(body.orientation) * body.bounding_radius;
    if (restart) world_.RestartContacts(body_index);
  }
}

}  // namespace rigid_body_sim::physics
