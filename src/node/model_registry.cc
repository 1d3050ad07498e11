#include "rigid_body_sim/node/model_registry.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "rigid_body_sim/node/names.h"

namespace rigid_body_sim::node {

using physics::BodyDef;
using physics::FormatNumber;
using physics::Pose;
using physics::Result;
using physics::Status;
using physics::Vec3;

namespace {

bool IsNameStart(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; }
bool IsNameChar(char c) { return IsNameStart(c) || (c >= '0' && c <= '9'); }

}  // namespace

Status ValidateModelName(const std::string& name) {
  if (name.empty()) return Status::Error("model name is empty");
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    if (i == 0 ? !IsNameStart(c) : !IsNameChar(c)) {
      std::string shown =
          (c >= 0x20 && c < 0x7f) ? std::string(1, c) : "\\x" + FormatNumber(int(c));
      return Status::Error("model name '" + name + "' has a bad character '" + shown +
                           "' at position " + std::to_string(i) +
                           "; names match [A-Za-z_][A-Za-z0-9_]*");
    }
  }
  if (name == names::kGroundName) {
    return Status::Error("model name '" + name + "' is reserved for the ground plane");
  }
  return Status::Ok();
}

Result<BodyDef> MakeBodyDef(const io::LoadedModel& model, const ModelSpec& spec,
                            const MaterialDefaults& defaults) {
  if (std::isnan(spec.friction)) return Result<BodyDef>::Error("friction is NaN");
  if (std::isnan(spec.restitution)) return Result<BodyDef>::Error("restitution is NaN");
  if (!std::isfinite(spec.friction) && spec.friction > 0.0) {
    return Result<BodyDef>::Error("friction is infinite");
  }
  if (spec.restitution > 1.0) {
    return Result<BodyDef>::Error("restitution " + FormatNumber(spec.restitution) +
                                  " is outside [0, 1]");
  }
  BodyDef def;
  def.is_static = spec.is_static || model.is_static;
  // The spawn pose is the URDF's `world` frame, as in Gazebo and
  // robot_state_publisher: a root fixed (or floating) to it sits at the
  // joint's <origin> from there.
  def.world_from_body = spec.root_state.world_from_frame * model.world_from_root;
  if (!def.is_static) {
    def.linear_velocity = spec.root_state.linear_velocity;
    def.angular_velocity = spec.root_state.angular_velocity;
    def.mass_properties = model.mass_properties;
  }
  def.shapes.reserve(model.shapes.size());
  for (const io::LoadedShape& loaded : model.shapes) {
    physics::ShapeDef shape = loaded.shape;
    if (spec.friction >= 0.0) {
      shape.material.friction = spec.friction;
    } else if (!loaded.friction_from_urdf) {
      shape.material.friction = defaults.friction;
    }
    shape.material.restitution = spec.restitution >= 0.0 ? spec.restitution : defaults.restitution;
    def.shapes.push_back(std::move(shape));
  }
  return def;
}

Result<physics::ArticulationDef> MakeArticulationSpec(const io::LoadedModel& model,
                                                      const ModelSpec& spec,
                                                      const physics::BodyDef& body_def,
                                                      std::vector<std::string>* warnings) {
  // The materials as the rigid body of the same model has them.
  io::LoadedModel with_materials = model;
  for (std::size_t i = 0; i < model.shapes.size(); ++i) {
    with_materials.shapes[i].shape.material = body_def.shapes[i].material;
  }
  Result<physics::ArticulationDef> made = io::MakeArticulationDef(with_materials, warnings);
  if (!made.ok()) return made;
  physics::ArticulationDef def = std::move(made).value();
  // MakeArticulationDef fixes a base without mass; a static spawn fixes any.
  def.fixed_base = def.fixed_base || spec.is_static;
  def.world_from_base = spec.root_state.world_from_frame * model.world_from_root;
  def.base_linear_velocity = def.fixed_base ? Vec3::Zero() : spec.root_state.linear_velocity;
  def.base_angular_velocity = def.fixed_base ? Vec3::Zero() : spec.root_state.angular_velocity;
  def.self_collide = spec.self_collide;
  return def;
}

FrameState LinkStateFromRoot(const FrameState& root, const Pose& root_from_link) {
  FrameState link;
  link.world_from_frame = root.world_from_frame * root_from_link;
  const Vec3 root_to_link_world = root.world_from_frame.rotation * root_from_link.translation;
  link.linear_velocity = root.linear_velocity + root.angular_velocity.cross(root_to_link_world);
  link.angular_velocity = root.angular_velocity;
  return link;
}

FrameState RootStateFromLink(const FrameState& link, const Pose& root_from_link) {
  FrameState root;
  root.world_from_frame = link.world_from_frame * root_from_link.Inverse();
  const Vec3 link_to_root_world =
      root.world_from_frame.translation - link.world_from_frame.translation;
  root.linear_velocity = link.linear_velocity + link.angular_velocity.cross(link_to_root_world);
  root.angular_velocity = link.angular_velocity;
  return root;
}

std::string FrameName(const std::string& model, const std::string& link) {
  return model + names::kFrameSeparator + link;
}

int LinkIndex(const Model& model, const std::string& link_name) {
  if (!model.link_index.empty()) {
    const auto found = model.link_index.find(link_name);
    return found == model.link_index.end() ? -1 : found->second;
  }
  for (std::size_t i = 0; i < model.links.size(); ++i) {
    if (model.links[i].link_name == link_name) return static_cast<int>(i);
  }
  return -1;
}

std::string TfFrame(const Model& model, const std::string& link) { return model.tf_prefix + link; }

namespace {

bool IsLetter(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }

}  // namespace

Result<std::string> ResolveRobotNamespace(const std::string& robot_namespace) {
  if (robot_namespace.empty() || robot_namespace == "/") return robot_namespace;
  std::string resolved = robot_namespace.front() == '/' ? robot_namespace : "/" + robot_namespace;
  if (resolved.back() == '/') resolved.pop_back();
  // Segments [A-Za-z][A-Za-z0-9_]*, as ROS graph names.
  bool segment_start = true;
  for (std::size_t i = 1; i < resolved.size(); ++i) {
    const char c = resolved[i];
    const bool ok = c == '/' ? !segment_start : (segment_start ? IsLetter(c) : IsNameChar(c));
    if (!ok) {
      return Result<std::string>::Error("robot_namespace '" + robot_namespace +
                                        "' is not a ROS namespace: each part must match "
                                        "[A-Za-z][A-Za-z0-9_]*");
    }
    segment_start = c == '/';
  }
  return resolved;
}

Result<std::string> ResolveTfPrefix(const std::string& name, const std::string& tf_prefix,
                                    TfMode mode) {
  // robot_state_publisher names the other links as the URDF does, so the
  // root it hangs them from is unprefixed too.
  if (tf_prefix.empty()) return mode == TfMode::kRoot ? "" : name + names::kFrameSeparator;
  if (tf_prefix == "/") return std::string();
  const bool allowed =
      tf_prefix.front() != '/' && std::all_of(tf_prefix.begin(), tf_prefix.end(), [](char c) {
        return IsNameChar(c) || c == '/' || c == '.' || c == '-';
      });
  if (!allowed) {
    return Result<std::string>::Error("tf_prefix '" + tf_prefix +
                                      "' may hold only [A-Za-z0-9_./-] and not start with '/' "
                                      "('/' alone: no prefix)");
  }
  return tf_prefix;
}

Result<TfMode> TfModeFromName(const std::string& mode) {
  if (mode.empty() || mode == "links") return TfMode::kLinks;
  if (mode == "root") return TfMode::kRoot;
  if (mode == "none") return TfMode::kNone;
  return Result<TfMode>::Error("tf_mode '" + mode + "' is not one of links, root and none");
}

Status ModelRegistry::Add(Model model) {
  if (models_.count(model.name) != 0) {
    return Status::Error("a model named '" + model.name + "' already exists");
  }
  if (model.bodies.empty()) model.bodies = {model.body};
  for (const physics::BodyId body : model.bodies) name_by_body_[Key(body)] = model.name;
  model.link_index.clear();
  for (std::size_t i = 0; i < model.links.size(); ++i) {
    model.link_index.emplace(model.links[i].link_name, static_cast<int>(i));
  }
  std::string name = model.name;
  models_.emplace(std::move(name), std::move(model));
  return Status::Ok();
}

bool ModelRegistry::Remove(const std::string& name) {
  const auto it = models_.find(name);
  if (it == models_.end()) return false;
  for (const physics::BodyId body : it->second.bodies) name_by_body_.erase(Key(body));
  models_.erase(it);
  return true;
}

const Model* ModelRegistry::Find(const std::string& name) const {
  const auto it = models_.find(name);
  return it == models_.end() ? nullptr : &it->second;
}

const Model* ModelRegistry::FindByBody(physics::BodyId body) const {
  const auto it = name_by_body_.find(Key(body));
  return it == name_by_body_.end() ? nullptr : Find(it->second);
}

Result<FrameRef> ModelRegistry::ResolveFrame(const std::string& frame) const {
  if (frame.empty()) return Result<FrameRef>::Error("name is empty");
  const std::size_t separator = frame.find(names::kFrameSeparator);
  const std::string model_name = frame.substr(0, separator);
  const Model* model = Find(model_name);
  if (model == nullptr) return Result<FrameRef>::Error("no model named '" + model_name + "'");
  if (separator == std::string::npos) return FrameRef{model, &model->links.front()};
  const std::string link_name = frame.substr(separator + 1);
  for (const io::LinkFrame& link : model->links) {
    if (link.link_name == link_name) return FrameRef{model, &link};
  }
  return Result<FrameRef>::Error("model '" + model_name + "' has no link named '" + link_name +
                                 "'");
}

std::string ModelRegistry::ShapeFrame(physics::BodyId body, int shape_index) const {
  const Model* model = FindByBody(body);
  if (model == nullptr) return "";
  for (std::size_t k = 0; k < model->bodies.size() && k < model->body_shape_links.size(); ++k) {
    if (model->bodies[k] != body) continue;
    const std::vector<std::string>& links = model->body_shape_links[k];
    assert(shape_index >= 0 && shape_index < static_cast<int>(links.size()));
    return FrameName(model->name, links[shape_index]);
  }
  return "";
}

void ModelRegistry::Clear() {
  models_.clear();
  name_by_body_.clear();
}

}  // namespace rigid_body_sim::node
