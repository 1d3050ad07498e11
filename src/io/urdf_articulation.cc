// A loaded URDF model as an articulation: links joined by fixed joints merge
// into one articulation link, each movable joint becomes a joint.
#include <map>
#include <string>

#include "rigid_body_sim/io/urdf_loader.h"

namespace rigid_body_sim::io {

using physics::ArticulationDef;
using physics::JointDef;
using physics::JointType;
using physics::MassProperties;
using physics::Pose;
using physics::Result;

namespace {

// A group without mass (a chain of URDF frames with no <inertial> and no
// collision) gets this much, so the joint-space inertia stays invertible.
constexpr double kPlaceholderMass = 1e-3;     // kg
constexpr double kPlaceholderInertia = 1e-7;  // kg m^2

JointType TypeOf(const std::string& urdf_type) {
  if (urdf_type == "prismatic") return JointType::kPrismatic;
  if (urdf_type == "continuous") return JointType::kContinuous;
  return JointType::kRevolute;
}

// A movable joint's own fields; its links and frame are the caller's.
JointDef JointDefOf(const JointInfo& joint) {
  JointDef def;
  def.name = joint.name;
  def.type = TypeOf(joint.type);
  def.axis = joint.axis;
  def.lower = joint.lower;
  def.upper = joint.upper;
  def.effort_limit = joint.effort;
  def.velocity_limit = joint.velocity;
  def.damping = joint.damping;
  def.friction = joint.friction;
  def.position = joint.position;
  def.mimic_multiplier = joint.mimic_multiplier;
  def.mimic_offset = joint.mimic_offset;
  return def;
}

// The mass of one articulation link (a group of URDF links joined by fixed
// joints): its parts combined, or the placeholder when it has none (with a
// warning, unless it is the base, whose mass a fixed base never uses).
MassProperties GroupMass(const std::vector<MassProperties>& parts, const std::string& root_name,
                         bool is_base, std::vector<std::string>* warnings) {
  if (!parts.empty()) return physics::CombineMassProperties(parts);
  if (!is_base) {
    warnings->push_back("link '" + root_name +
                        "' and the links fixed to it have no mass; it moves as " +
                        physics::FormatNumber(kPlaceholderMass) + " kg");
  }
  MassProperties placeholder;
  placeholder.mass = kPlaceholderMass;
  placeholder.inertia_about_com = physics::Mat3::Identity() * kPlaceholderInertia;
  return placeholder;
}

}  // namespace

Result<ArticulationDef> MakeArticulationDef(const LoadedModel& model,
                                            std::vector<std::string>* warnings) {
  std::map<std::string, int> group_of_link;
  std::map<std::string, const LinkFrame*> frame_of_link;
  for (const LinkFrame& link : model.links) frame_of_link[link.link_name] = &link;
  std::vector<std::string> group_root{model.root_link};
  group_of_link[model.root_link] = 0;
  std::map<std::string, int> joint_index;
  ArticulationDef def;
  for (const JointInfo& joint : model.joints) {
    const int parent_group = group_of_link.at(joint.parent_link);
    if (joint.type == "fixed") {
      group_of_link[joint.child_link] = parent_group;
      continue;
    }
    const int child_group = static_cast<int>(group_root.size());
    group_root.push_back(joint.child_link);
    group_of_link[joint.child_link] = child_group;
    // The joint frame in the parent group's frame: the parent link's pose in
    // its group (at the initial positions, fixed within a group), then the
    // joint's <origin>.
    const Pose root_from_parent_group = frame_of_link.at(group_root[parent_group])->root_from_link;
    const Pose root_from_parent = frame_of_link.at(joint.parent_link)->root_from_link;
    JointDef& def_joint = def.joints.emplace_back(JointDefOf(joint));
    def_joint.parent_link = parent_group;
    def_joint.child_link = child_group;
    def_joint.parent_from_joint =
        root_from_parent_group.Inverse() * root_from_parent * joint.parent_from_joint;
    joint_index[joint.name] = static_cast<int>(def.joints.size()) - 1;
  }
  // Leaders may come after their mimics in tree order: linked once all are
  // numbered (the loader checked that each leader is a movable joint).
  for (const JointInfo& joint : model.joints) {
    if (joint.mimic_joint.empty()) continue;
    def.joints[joint_index.at(joint.name)].mimic_joint = joint_index.at(joint.mimic_joint);
  }

  std::vector<std::vector<MassProperties>> parts(group_root.size());
  def.links.resize(group_root.size());
  for (std::size_t g = 0; g < group_root.size(); ++g) def.links[g].name = group_root[g];
  auto group_from = [&](const std::string& link_name) {
    const int group = group_of_link.at(link_name);
    return frame_of_link.at(group_root[group])->root_from_link.Inverse();
  };
  for (const LinkFrame& link : model.links) {
    if (link.mass_in_link.mass <= 0.0) continue;
    parts[group_of_link.at(link.link_name)].push_back(physics::TransformMassProperties(
        link.mass_in_link, group_from(link.link_name) * link.root_from_link));
  }
  for (const LoadedShape& shape : model.shapes) {
    physics::ShapeDef in_group = shape.shape;
    in_group.body_from_shape = group_from(shape.link_name) * shape.shape.body_from_shape;
    def.links[group_of_link.at(shape.link_name)].shapes.push_back(in_group);
  }
  // A base without mass (Bullet's mass 0, or a movable joint to 'world')
  // cannot float: the articulation is fixed where it is spawned.
  def.fixed_base = model.is_static || parts[0].empty();
  if (parts[0].empty() && !model.is_static) {
    warnings->push_back("link '" + group_root[0] + "' and the links fixed to it have no mass; " +
                        "the articulation's base is fixed where it is spawned");
  }
  for (std::size_t g = 0; g < group_root.size(); ++g) {
    def.links[g].mass_properties = GroupMass(parts[g], group_root[g], g == 0, warnings);
  }
  def.world_from_base = model.world_from_root;
  return def;
}

}  // namespace rigid_body_sim::io
