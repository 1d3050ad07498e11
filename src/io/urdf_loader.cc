#include "rigid_body_sim/io/urdf_loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <tuple>
#include <utility>

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_model/model.h>
#include <urdf_parser/urdf_parser.h>

#include "io/gazebo_plugins.h"
#include "io/mesh_collision_modes.h"
#include "io/urdf_checks.h"
#include "io/urdf_elements.h"
#include "io/urdf_load_options.h"
#include "io/urdf_meshes.h"

namespace rigid_body_sim::io {
namespace {

using physics::ConvexPolyhedron;
using physics::FormatNumber;
using physics::MassProperties;
using physics::Mat3;
using physics::Pose;
using physics::Quat;
using physics::Result;
using physics::Status;
using physics::Vec3;

constexpr char kWorldLink[] = "world";

// Builds one model; keeps caches across the links of that model.
class ModelBuilder {
 public:
  ModelBuilder(const UrdfLoadOptions& options, UriResolver resolver)
      : options_(options), resolver_(resolver), meshes_(options, resolver) {}

  Result<LoadedModel> Build(const std::string& unpadded_xml) {
    // TinyXML (ours and urdfdom's) steps over a UTF-8 sequence by the length
    // its lead byte announces (at most 4) without looking for the end of the
    // text: urdf_loader_fuzzer caught it reading 12 bytes past the end of a
    // document ending in such a byte. Trailing NULs keep those reads inside
    // the string, and end the name or value being read.
    const std::string xml = unpadded_xml + std::string(16, '\0');
    TiXmlDocument document;
    document.Parse(xml.c_str());
    if (document.Error()) {
      return Result<LoadedModel>::Error(
          "malformed URDF XML at line " + std::to_string(document.ErrorRow()) + ", column " +
          std::to_string(document.ErrorCol()) + ": " + document.ErrorDesc());
    }
    TiXmlElement* robot = document.RootElement();
    if (robot == nullptr || robot->ValueStr() != "robot") {
      return Result<LoadedModel>::Error("URDF root element must be <robot>");
    }
    if (Status status = CheckUrdfDocument(*robot, options_); !status.ok()) return status;
    massless_ = EveryLinkIsMassless(*robot);
    Result<std::map<std::string, double>> friction = ReadGazeboFriction(*robot);
    if (!friction.ok()) return friction.status();
    friction_ = std::move(friction).value();
    Result<MeshCollisionModes> modes = ReadMeshCollisionModes(*robot);
    if (!modes.ok()) return modes.status();
    mesh_modes_ = std::move(modes).value();
    ignored_ = IgnoredElements(*robot);

    // urdfdom's reading of the document, with the products of inertia a
    // description left out written in as 0.
    std::string for_urdfdom = xml;
    document_warnings_.clear();
    for (const std::string& link : FillOmittedProductsOfInertia(robot)) {
      document_warnings_.push_back("link " + Quoted(link) +
                                   " <inertia> leaves out products of inertia; read as 0");
    }
    if (!document_warnings_.empty()) {
      TiXmlPrinter printer;
      document.Accept(&printer);
      for_urdfdom = std::string(printer.CStr()) + std::string(16, '\0');
    }

    urdf::ModelInterfaceSharedPtr model = ParseWithUrdfdom(for_urdfdom);
    if (model == nullptr) {
      const std::string reason = UrdfdomMessages(for_urdfdom);
      return Result<LoadedModel>::Error("urdfdom rejected the URDF: " +
                                        (reason.empty() ? "no reason given" : reason));
    }
    Result<LoadedModel> loaded = BuildModel(*model);
    if (!loaded.ok()) return loaded;
    if (Status status = AddGazeboPlugins(*robot, &loaded.value()); !status.ok()) return status;
    return loaded;
  }

 private:
  // urdfdom's model of the document, parsed with console_bridge muted (see
  // ConsoleCapture): nothing from the document reaches a printf format.
  static urdf::ModelInterfaceSharedPtr ParseWithUrdfdom(const std::string& xml) {
    ConsoleCapture muted(ConsoleCapture::Mode::kMuted);
    return urdf::parseURDF(xml);
  }

  // Why urdfdom refused the document: parsed again with its messages
  // captured, every '%' written as '?' first so none can act as a printf
  // conversion in the messages that use document text as their format.
  static std::string UrdfdomMessages(std::string xml) {
    const bool replaced = xml.find('%') != std::string::npos;
    std::replace(xml.begin(), xml.end(), '%', '?');
    ConsoleCapture capture(ConsoleCapture::Mode::kCapture);
    urdf::parseURDF(xml);
    if (capture.text().empty() || !replaced) return capture.text();
    return capture.text() + " (each '%' shown as '?')";
  }

  Result<LoadedModel> BuildModel(const urdf::ModelInterface& model) {
    if (Status status = CheckJoints(model); !status.ok()) return status;
    for (const auto& [name, link] : model.links_) {
      if (name == kWorldLink && link != model.getRoot()) {
        return Result<LoadedModel>::Error("link 'world' must be the root of the model");
      }
    }

    LoadedModel loaded;
    loaded.name = model.getName();
    loaded.warnings = document_warnings_;
    loaded.ignored = ignored_;
    urdf::LinkConstSharedPtr body_root = model.getRoot();
    if (body_root->name == kWorldLink) {
      loaded.world_link = true;
      if (body_root->child_links.size() != 1) {
        return Result<LoadedModel>::Error("link 'world' must have exactly one child link, has " +
                                          std::to_string(body_root->child_links.size()));
      }
      // A fixed joint to the world makes the model static; a floating one
      // leaves its root free.
      const int world_type = body_root->child_links.front()->parent_joint->type;
      loaded.is_static = world_type == urdf::Joint::FIXED;
      // A movable joint to the world keeps 'world' as the model's root: a
      // base without mass, which MakeArticulationDef fixes where the model
      // is spawned.
      if (loaded.is_static || world_type == urdf::Joint::FLOATING) {
        if (!body_root->collision_array.empty() || body_root->inertial != nullptr) {
          loaded.warnings.push_back(
              "link 'world' stands for the fixed world; its <collision> and <inertial> are "
              "ignored");
        }
        const urdf::Joint& world_joint = *body_root->child_links.front()->parent_joint;
        loaded.world_from_root = ToPose(world_joint.parent_to_joint_origin_transform);
        body_root = body_root->child_links.front();
      }
    }
    if (massless_ && !loaded.is_static) {
      loaded.is_static = true;
      loaded.warnings.push_back("every link has mass 0: the model is static");
    }
    loaded.root_link = body_root->name;
    // Links below a movable joint move even when the base is fixed, so an
    // articulated model's meshes are hulls or pieces, never triangles.
    bool moving_links = false;
    for (const auto& [name, joint] : model.joints_) {
      moving_links = moving_links || (options_.articulate && IsWeldable(joint->type));
    }
    static_model_ = (loaded.is_static || options_.spawn_static) && !moving_links;
    meshes_.set_max_aspect_ratio(MaxAspectRatio(static_model_));

    std::vector<MassProperties> parts_in_root;
    const Status status = AddLinks(*body_root, &loaded, &parts_in_root);
    if (!status.ok()) return status;
    loaded.warnings.insert(loaded.warnings.end(), meshes_.warnings().begin(),
                           meshes_.warnings().end());
    if (loaded.shapes.empty()) {
      return Result<LoadedModel>::Error("model " + Quoted(loaded.name) +
                                        " has no <collision> elements");
    }
    loaded.mass_properties = physics::CombineMassProperties(parts_in_root);
    // A static model needs no mass: a bin of triangle meshes has none.
    if (!loaded.is_static && !static_model_) {
      const Status mass_status = physics::ValidateMassProperties(loaded.mass_properties);
      if (!mass_status.ok()) {
        return Result<LoadedModel>::Error("model " + Quoted(loaded.name) +
                                          " has invalid mass properties: " + mass_status.message());
      }
    }
    return loaded;
  }

  // Refuses joints that cannot be welded, joint positions that name no
  // weldable joint or lie outside its limits or kMaxJointPosition, and
  // mimic joints that would move beyond kMaxJointPosition or
  // kMaxJointSpeed (CheckMimicJoints); then sets the initial positions.
  Status CheckJoints(const urdf::ModelInterface& model) {
    for (const auto& [name, joint] : model.joints_) {
      if (joint->type == urdf::Joint::FIXED) continue;
      if (joint->type == urdf::Joint::FLOATING && joint->parent_link_name == kWorldLink) continue;
      if (!IsWeldable(joint->type)) {
        return Status::Error("joint " + Quoted(name) + " is " + JointTypeName(joint->type) +
                             "; supported joints are fixed, revolute, continuous and prismatic" +
                             " (a model without a joint to 'world' has a floating base)");
      }
      if (!options_.articulate && !options_.weld_movable_joints) {
        return Status::Error("joint " + Quoted(name) + " is " + JointTypeName(joint->type) +
                             "; this load takes fixed joints only");
      }
      if (joint->mimic != nullptr) {
        const auto leader = model.joints_.find(joint->mimic->joint_name);
        if (leader == model.joints_.end() || !IsWeldable(leader->second->type) ||
            leader->second->mimic != nullptr) {
          return Status::Error("joint " + Quoted(name) + " mimics " +
                               Quoted(joint->mimic->joint_name) +
                               ", which is not a movable joint that mimics none");
        }
      }
    }
    for (const auto& [name, position] : options_.joint_positions) {
      const auto found = model.joints_.find(name);
      if (found == model.joints_.end() || !IsWeldable(found->second->type) ||
          found->second->mimic != nullptr) {
        std::string movable;
        for (const auto& [other, joint] : model.joints_) {
          if (IsWeldable(joint->type)) movable += (movable.empty() ? "" : ", ") + Quoted(other);
        }
        return Status::Error("joint " + Quoted(name) + " is not a movable joint of the model" +
                             (movable.empty() ? " (it has none)" : "; movable: " + movable));
      }
      const urdf::Joint& joint = *found->second;
      if (!std::isfinite(position)) {
        return Status::Error("joint " + Quoted(name) + " position is not finite");
      }
      const char* unit = joint.type == urdf::Joint::PRISMATIC ? " m" : " rad";
      if (!(std::abs(position) <= kMaxJointPosition)) {
        return Status::Error("joint " + Quoted(name) + " position " + FormatNumber(position) +
                             unit + " is outside the allowed range [" +
                             FormatNumber(-kMaxJointPosition) + ", " +
                             FormatNumber(kMaxJointPosition) + "]");
      }
      if (joint.type != urdf::Joint::CONTINUOUS && joint.limits != nullptr &&
          joint.limits->lower <= joint.limits->upper &&
          (position < joint.limits->lower || position > joint.limits->upper)) {
        return Status::Error("joint " + Quoted(name) + " position " + FormatNumber(position) +
                             unit + " is outside its limits [" + FormatNumber(joint.limits->lower) +
                             ", " + FormatNumber(joint.limits->upper) + "]");
      }
    }
    if (Status status = CheckMimicJoints(model); !status.ok()) return status;
    return SetInitialPositions(model);
  }

  // The position given for a joint that mimics none; if none, 0 brought
  // within the joint's limits (a published arm's elbow may have
  // [-2.1, -0.03]).
  double InitialPosition(const urdf::Joint& joint) const {
    const auto given = options_.joint_positions.find(joint.name);
    if (given != options_.joint_positions.end()) return given->second;
    if (joint.limits == nullptr || joint.type == urdf::Joint::CONTINUOUS ||
        joint.limits->lower > joint.limits->upper) {
      return 0.0;
    }
    return std::clamp(0.0, joint.limits->lower, joint.limits->upper);
  }

  // initial_positions_ for every movable joint; a mimic joint's follows its
  // leader's, as the simulation has it, and is refused beyond
  // kMaxJointPosition (CheckMimicJoints bounds it over a limited leader's
  // range; a continuous leader's given position is known only here).
  Status SetInitialPositions(const urdf::ModelInterface& model) {
    initial_positions_.clear();
    for (const auto& [name, joint] : model.joints_) {
      if (IsWeldable(joint->type) && joint->mimic == nullptr) {
        initial_positions_[name] = InitialPosition(*joint);
      }
    }
    for (const auto& [name, joint] : model.joints_) {
      if (!IsWeldable(joint->type) || joint->mimic == nullptr) continue;
      const urdf::JointMimic& mimic = *joint->mimic;
      const double leader = initial_positions_.at(mimic.joint_name);
      const double position = mimic.multiplier * leader + mimic.offset;
      if (!(std::abs(position) <= kMaxJointPosition)) {
        return Status::Error(
            "joint " + Quoted(name) + " <mimic> initial position " + FormatNumber(position) +
            (joint->type == urdf::Joint::PRISMATIC ? " m" : " rad") + " (multiplier " +
            FormatNumber(mimic.multiplier) + " times leader " + Quoted(mimic.joint_name) + " at " +
            FormatNumber(leader) + ", plus offset " + FormatNumber(mimic.offset) +
            ") is outside the allowed range [" + FormatNumber(-kMaxJointPosition) + ", " +
            FormatNumber(kMaxJointPosition) + "]");
      }
      initial_positions_[name] = position;
    }
    return Status::Ok();
  }

  static bool IsWeldable(int type) {
    return type == urdf::Joint::REVOLUTE || type == urdf::Joint::CONTINUOUS ||
           type == urdf::Joint::PRISMATIC;
  }

  // The child frame of a welded joint in its joint frame: a turn about the
  // axis, or a slide along it.
  Pose JointMotion(const urdf::Joint& joint, JointInfo* info, LoadedModel* loaded) const {
    info->parent_from_joint = ToPose(joint.parent_to_joint_origin_transform);
    if (joint.type == urdf::Joint::FIXED) return Pose::Identity();
    loaded->articulated = options_.articulate;
    const auto initial = initial_positions_.find(joint.name);
    const double position = initial == initial_positions_.end() ? 0.0 : initial->second;
    info->position = position;
    if (!options_.articulate) {
      loaded->warnings.push_back("joint " + Quoted(joint.name) + " is " +
                                 JointTypeName(joint.type) + "; welded at " +
                                 FormatNumber(position));
    }
    Vec3 axis(joint.axis.x, joint.axis.y, joint.axis.z);
    // CheckUrdfDocument refused a zero or non-finite axis; scaled first so
    // that an axis of 1e300 has a finite length.
    if (!(axis.cwiseAbs().maxCoeff() > 0.0) || !axis.allFinite()) axis = Vec3::UnitX();
    axis /= axis.cwiseAbs().maxCoeff();
    axis.normalize();
    info->axis = axis;
    if (joint.limits != nullptr) {
      // Bullet reads lower > upper as no limit, and descriptions written
      // for it say so (lower 1, upper 0).
      if (joint.type != urdf::Joint::CONTINUOUS && joint.limits->lower <= joint.limits->upper) {
        info->lower = joint.limits->lower;
        info->upper = joint.limits->upper;
      } else if (joint.type != urdf::Joint::CONTINUOUS) {
        loaded->warnings.push_back("joint " + Quoted(joint.name) + " <limit> lower " +
                                   FormatNumber(joint.limits->lower) + " > upper " +
                                   FormatNumber(joint.limits->upper) + ": no position limit");
      }
      // URDF's 0 means "not given" for effort and velocity in many
      // descriptions; it is taken as no limit rather than a locked joint.
      if (joint.limits->effort > 0.0) info->effort = joint.limits->effort;
      if (joint.limits->velocity > 0.0) info->velocity = joint.limits->velocity;
    }
    if (joint.dynamics != nullptr) {
      info->damping = joint.dynamics->damping;
      info->friction = joint.dynamics->friction;
    }
    if (joint.mimic != nullptr) {
      info->mimic_joint = joint.mimic->joint_name;
      info->mimic_multiplier = joint.mimic->multiplier;
      info->mimic_offset = joint.mimic->offset;
    }
    if (joint.type == urdf::Joint::PRISMATIC) return Pose{axis * position, Quat::Identity()};
    return Pose{Vec3::Zero(), Quat(Eigen::AngleAxisd(position, axis))};
  }

  // Adds `root` and, through their (welded) joints, all links below it, in
  // depth-first order with an explicit stack: a chain of thousands of links
  // must not overflow the call stack. A joint is recorded when its child is
  // visited, so the joints come in the depth-first order of their links.
  Status AddLinks(const urdf::Link& root, LoadedModel* loaded,
                  std::vector<MassProperties>* parts_in_root) {
    struct Pending {
      const urdf::Link* link;
      Pose root_from_link;
      std::optional<JointInfo> joint;  // the joint to the link, none for the root
    };
    std::vector<Pending> pending;
    pending.push_back({&root, Pose::Identity(), std::nullopt});
    while (!pending.empty()) {
      Pending next = std::move(pending.back());
      pending.pop_back();
      if (next.joint) loaded->joints.push_back(std::move(*next.joint));
      const urdf::Link& link = *next.link;
      if (Status status = AddLink(link, next.root_from_link, loaded, parts_in_root); !status.ok()) {
        return status;
      }
      // Pushed in reverse, so the first child is visited next.
      for (auto joint = link.child_joints.rbegin(); joint != link.child_joints.rend(); ++joint) {
        urdf::LinkConstSharedPtr child;
        for (const urdf::LinkSharedPtr& candidate : link.child_links) {
          if (candidate->name == (*joint)->child_link_name) child = candidate;
        }
        if (child == nullptr) {
          return Status::Error("joint " + Quoted((*joint)->name) + " has no child link");
        }
        JointInfo info;
        info.name = (*joint)->name;
        info.type = JointTypeName((*joint)->type);
        info.parent_link = link.name;
        info.child_link = child->name;
        const Pose root_from_child = next.root_from_link *
                                     ToPose((*joint)->parent_to_joint_origin_transform) *
                                     JointMotion(**joint, &info, loaded);
        pending.push_back({child.get(), root_from_child, std::move(info)});
      }
    }
    return Status::Ok();
  }

  // Adds the shapes and the mass of one link.
  Status AddLink(const urdf::Link& link, const Pose& root_from_link, LoadedModel* loaded,
                 std::vector<MassProperties>* parts_in_root) {
    const std::size_t link_index = loaded->links.size();
    loaded->links.push_back(LinkFrame{link.name, root_from_link, 0.0, MassProperties{}});
    const auto friction = friction_.find(link.name);

    std::vector<MassProperties> geometry_parts_in_link;
    for (size_t i = 0; i < link.collision_array.size(); ++i) {
      const urdf::Collision& collision = *link.collision_array[i];
      const std::string where =
          "link " + Quoted(link.name) + " <collision> " +
          (collision.name.empty() ? std::to_string(i) : Quoted(collision.name));
      if (collision.geometry == nullptr) return Status::Error(where + " has no <geometry>");
      const MeshCollision mode = ModeOf(mesh_modes_, link.name, collision.name);
      Result<ShapeWithMass> shape = MakeShape(*collision.geometry, where, mode);
      if (!shape.ok()) return shape.status();
      const Pose link_from_shape = ToPose(collision.origin);
      for (const physics::ShapeGeometry& geometry : shape->geometry) {
        LoadedShape loaded_shape;
        loaded_shape.shape.geometry = geometry;
        loaded_shape.shape.body_from_shape = root_from_link * link_from_shape;
        loaded_shape.link_name = link.name;
        if (friction != friction_.end()) {
          loaded_shape.shape.material.friction = friction->second;
          loaded_shape.friction_from_urdf = true;
        }
        loaded->shapes.push_back(std::move(loaded_shape));
      }
      geometry_parts_in_link.push_back(
          physics::TransformMassProperties(shape->mass_in_shape_frame, link_from_shape));
    }

    // Overlapping collision elements count twice; a URDF that needs exact
    // mass properties for overlapping geometry states its <inertial>.
    const MassProperties from_geometry = physics::CombineMassProperties(geometry_parts_in_link);
    if (link.inertial != nullptr) {
      Result<InertialReading> inertial =
          ReadInertial(link, from_geometry, options_.balance_inertia);
      if (!inertial.ok()) return inertial.status();
      if (!inertial->warning.empty()) loaded->warnings.push_back(inertial->warning);
      loaded->links[link_index].mass = inertial->in_link.mass;
      loaded->links[link_index].mass_in_link = inertial->in_link;
      if (inertial->in_link.mass > 0.0) {
        parts_in_root->push_back(
            physics::TransformMassProperties(inertial->in_link, root_from_link));
      }
    } else if (!geometry_parts_in_link.empty()) {
      loaded->links[link_index].mass = from_geometry.mass;
      loaded->links[link_index].mass_in_link = from_geometry;
      parts_in_root->push_back(physics::TransformMassProperties(from_geometry, root_from_link));
      if (!loaded->is_static) {
        loaded->warnings.push_back("link " + Quoted(link.name) +
                                   " has no <inertial>; mass computed from its collision "
                                   "geometry at " +
                                   FormatNumber(options_.default_density) + " kg/m^3");
      }
    }
    return Status::Ok();
  }

  Result<ShapeWithMass> MakeShape(const urdf::Geometry& geometry, const std::string& where,
                                  MeshCollision mode) {
    const double density = options_.default_density;
    switch (geometry.type) {
      case urdf::Geometry::SPHERE: {
        const double radius = static_cast<const urdf::Sphere&>(geometry).radius;
        if (!(radius >= kMinShapeSize && radius <= kMaxShapeSize)) {
          return Result<ShapeWithMass>::Error(where + " <sphere> radius " + FormatNumber(radius) +
                                              " m is outside the allowed range [" +
                                              FormatNumber(kMinShapeSize) + ", " +
                                              FormatNumber(kMaxShapeSize) + "] m");
        }
        return ShapeWithMass{{physics::Sphere{radius}},
                             physics::SphereMassProperties(density, radius)};
      }
      case urdf::Geometry::BOX: {
        const urdf::Vector3& dim = static_cast<const urdf::Box&>(geometry).dim;
        const Vec3 size(dim.x, dim.y, dim.z);
        if (!PositiveFinite(size.x()) || !PositiveFinite(size.y()) || !PositiveFinite(size.z())) {
          return Result<ShapeWithMass>::Error(where + ": box size must be positive on every axis");
        }
        if (Status status =
                CheckShapeExtents(size, where + " <box>", MaxAspectRatio(static_model_));
            !status.ok()) {
          return status;
        }
        Result<ConvexPolyhedron> box = physics::TryMakeBoxPolyhedron(size);
        if (!box.ok()) return Result<ShapeWithMass>::Error(where + ": " + box.message());
        return ShapeWithMass{{std::make_shared<const ConvexPolyhedron>(std::move(box).value())},
                             physics::BoxMassProperties(density, size)};
      }
      case urdf::Geometry::CYLINDER: {
        const auto& cylinder = static_cast<const urdf::Cylinder&>(geometry);
        if (!PositiveFinite(cylinder.radius) || !PositiveFinite(cylinder.length)) {
          return Result<ShapeWithMass>::Error(where +
                                              ": cylinder radius and length must be positive");
        }
        const double diameter = 2.0 * cylinder.radius;
        if (Status status = CheckShapeExtents(Vec3(diameter, diameter, cylinder.length),
                                              where + " <cylinder>", MaxAspectRatio(static_model_));
            !status.ok()) {
          return status;
        }
        return ShapeWithMass{
            {physics::Cylinder{cylinder.radius, 0.5 * cylinder.length}},
            physics::CylinderMassProperties(density, cylinder.radius, cylinder.length)};
      }
      case urdf::Geometry::MESH: {
        const auto& mesh = static_cast<const urdf::Mesh&>(geometry);
        const Vec3 scale(mesh.scale.x, mesh.scale.y, mesh.scale.z);
        if (mode == MeshCollision::kTriangles && !static_model_) {
          return Result<ShapeWithMass>::Error(
              where +
              ": <mesh_collision> 'triangles' needs a static model (is_static, or fixed "
              "to 'world'); a moving mesh collides as its 'hull' or its 'decomposition'");
        }
        if (mode == MeshCollision::kTriangles ||
            (mode == MeshCollision::kDefault && static_model_)) {
          return meshes_.Triangles(mesh.filename, scale, where);
        }
        if (mode == MeshCollision::kHull) return meshes_.Hull(mesh.filename, scale, where);
        // A moving mesh that is clearly not convex is decomposed by default.
        return meshes_.Pieces(
            mesh.filename, scale,
            mode == MeshCollision::kDecomposition ? PiecesRule::kAlways : PiecesRule::kAuto, where);
      }
    }
    return Result<ShapeWithMass>::Error(where + ": unknown geometry type");
  }

  const UrdfLoadOptions& options_;
  UriResolver resolver_;
  std::map<std::string, double> friction_;
  std::map<std::string, double> initial_positions_;  // rad or m, by movable joint (CheckJoints)
  MeshCollisionModes mesh_modes_;
  bool static_model_ = false;                   // fixed to `world`, massless, or spawned static
  bool massless_ = false;                       // every link states mass 0
  std::vector<std::string> document_warnings_;  // what reading the XML itself changed
  std::vector<std::string> ignored_;            // IgnoredElements: the transmissions
  UrdfMeshes meshes_;
};

}  // namespace

Result<LoadedModel> LoadUrdfString(const std::string& xml, const UrdfLoadOptions& options) {
  const Status status = ValidateLoadOptions(options);
  if (!status.ok()) return status;
  const Result<std::string> urdf = ExpandedDescription("", xml, options);
  if (!urdf.ok()) return urdf.status();
  return ModelBuilder(options, ResolverOrDefault(options)).Build(*urdf);
}

Result<LoadedModel> LoadUrdfFile(const std::string& path, const UrdfLoadOptions& options) {
  const Status status = ValidateLoadOptions(options);
  if (!status.ok()) return status;
  // Checked before reading: /dev/zero would fill the memory, a FIFO would
  // block the caller.
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    return Result<LoadedModel>::Error("URDF file " + Quoted(path) +
                                      " does not exist or is not a regular file");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error || size > options.max_file_bytes) {
    return Result<LoadedModel>::Error("URDF file " + Quoted(path) + " size " +
                                      std::to_string(size) + " bytes is above the limit " +
                                      std::to_string(options.max_file_bytes));
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) return Result<LoadedModel>::Error("URDF file " + Quoted(path) + " cannot be read");
  std::ostringstream contents;
  contents << file.rdbuf();

  // Relative mesh paths are relative to the URDF file.
  const std::filesystem::path directory = std::filesystem::path(path).parent_path();
  UriResolver resolve = ResolverOrDefault(options);
  UriResolver relative_to_file = [resolve,
                                  directory](const std::string& uri) -> Result<std::string> {
    Result<std::string> resolved = resolve(uri);
    if (!resolved.ok() || std::filesystem::path(*resolved).is_absolute()) return resolved;
    return (directory / *resolved).string();
  };
  const Result<std::string> urdf = ExpandedDescription(path, contents.str(), options);
  if (!urdf.ok())
    return Result<LoadedModel>::Error("URDF file " + Quoted(path) + ": " + urdf.message());
  Result<LoadedModel> model = ModelBuilder(options, relative_to_file).Build(*urdf);
  if (!model.ok()) {
    return Result<LoadedModel>::Error("URDF file " + Quoted(path) + ": " + model.message());
  }
  return model;
}

}  // namespace rigid_body_sim::io
