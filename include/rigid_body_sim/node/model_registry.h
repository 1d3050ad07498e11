// The node's models: what a spawn asks for, how a loaded URDF becomes a body,
// and the registry of spawned models by name. ROS-free.
#ifndef RIGID_BODY_SIM_NODE_MODEL_REGISTRY_H_
#define RIGID_BODY_SIM_NODE_MODEL_REGISTRY_H_

#include <cstdint>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::node {

// Pose and twist of a frame in the world frame. The twist is the velocity of
// the frame's origin plus the angular velocity.
struct FrameState {
  physics::Pose world_from_frame;
  physics::Vec3 linear_velocity = physics::Vec3::Zero();   // m/s, world
  physics::Vec3 angular_velocity = physics::Vec3::Zero();  // rad/s, world
};

// Which of a model's frames the node publishes on tf.
enum class TfMode {
  kLinks,  // every link: the world to the root, then the URDF tree
  kRoot,   // the world to the root link only; robot_state_publisher does the rest
  kNone,   // none
};

// What a caller asks to spawn, from the Spawn service or the ~models parameter.
struct ModelSpec {
  std::string name;       // [A-Za-z_][A-Za-z0-9_]*
  std::string urdf;       // URDF XML; when empty, urdf_path is read
  std::string urdf_path;  // file path, file:// or package:// URI
  FrameState root_state;  // of the root link
  bool is_static = false;
  double friction = -1.0;     // >= 0 overrides every shape; < 0: URDF or the default
  double restitution = -1.0;  // >= 0 overrides every shape; < 0: the default
  // rad or m by movable joint name: where the joints start (and return to
  // on a reset). The loader checks names and limits.
  std::map<std::string, double> joint_positions;
  // Links of an articulated model collide with each other (never two
  // joined by one joint), like Gazebo's <self_collide>.
  bool self_collide = false;
  // Where its joint topics live: "" under ~<name>/, "/" global, else that
  // namespace (ValidateRobotNamespace).
  std::string robot_namespace;
  std::string tf_prefix;  // "": "<name>/"; "/": none; else as given
  TfMode tf_mode = TfMode::kLinks;
  bool hold = false;                    // servos hold the spawn positions until commanded
  std::vector<std::string> xacro_args;  // name:=value
};

// "" stays "" (the node's private namespace); any other is made absolute
// without a trailing '/': "arm" -> "/arm", "/" -> "/". Fails naming the
// field on a name ROS does not allow ([A-Za-z][A-Za-z0-9_]* segments).
physics::Result<std::string> ResolveRobotNamespace(const std::string& robot_namespace);
// The prefix of the model's tf frames: for "", "<name>/" (none in
// TfMode::kRoot, where robot_state_publisher names the links as the URDF
// does); "" for "/"; else `tf_prefix`, which may hold only [A-Za-z0-9_./-]
// and not start with '/'.
physics::Result<std::string> ResolveTfPrefix(const std::string& name, const std::string& tf_prefix,
                                             TfMode mode);
// "" and "links", "root", "none".
physics::Result<TfMode> TfModeFromName(const std::string& mode);

// Materials of shapes the spec and the URDF leave open.
struct MaterialDefaults {
  double friction = 0.5;     // Coulomb mu, dimensionless, >= 0
  double restitution = 0.0;  // e, in [0, 1]
};

// Checks name against [A-Za-z_][A-Za-z0-9_]* and the reserved name 'ground'.
physics::Status ValidateModelName(const std::string& name);

// The body of a loaded URDF model placed as the spec asks. Friction: the
// spec's if >= 0, else the URDF's (gazebo mu1) where given, else the default;
// restitution: the spec's if >= 0, else the default. A static body (asked
// for, or fixed to 'world' in the URDF) gets zero velocity. Fails on an
// out-of-range friction or restitution, naming it.
physics::Result<physics::BodyDef> MakeBodyDef(const io::LoadedModel& model, const ModelSpec& spec,
                                              const MaterialDefaults& defaults);

// The articulation of an articulated model placed as the spec asks, with
// the materials of `body_def` (MakeBodyDef's for the same model and spec)
// on its shapes; `warnings` gets the loader's notes on links without mass.
physics::Result<physics::ArticulationDef> MakeArticulationSpec(const io::LoadedModel& model,
                                                               const ModelSpec& spec,
                                                               const physics::BodyDef& body_def,
                                                               std::vector<std::string>* warnings);

// Rigid-body velocity transfer between two frames of one body:
// v_link = v_root + w x (p_link - p_root), w shared.
FrameState LinkStateFromRoot(const FrameState& root, const physics::Pose& root_from_link);
FrameState RootStateFromLink(const FrameState& link, const physics::Pose& root_from_link);

// '<model>/<link>'.
std::string FrameName(const std::string& model, const std::string& link);

struct Model {
  std::string name;
  physics::BodyId body;  // the root link's body
  // An articulated model's articulation (invalid for a rigid model), its
  // bodies (one per articulation link; {body} for a rigid model), each
  // body's shapes' links, and per entry of `links` its body and pose in it.
  physics::ArticulationId articulation;
  std::vector<physics::BodyId> bodies;
  std::vector<std::vector<std::string>> body_shape_links;
  std::vector<int> link_body;
  std::vector<physics::Pose> body_from_link;
  // Movable joints in tree order (mimic joints included): joint_states'
  // names, and where each started.
  std::vector<std::string> joint_names;
  std::vector<double> spawn_joint_positions;
  bool is_static = false;
  std::vector<io::LinkFrame> links;   // every link of the body, root first, with masses
  std::vector<io::JointInfo> joints;  // every joint but one to 'world'
  double mass = 0.0;                  // kg, of the body; 0 when static
  FrameState spawn_state;             // of the root link, restored by a reset
  std::string robot_namespace;        // resolved: "" for ~<name>/
  std::string tf_prefix;              // resolved
  TfMode tf_mode = TfMode::kLinks;
  bool hold = false;  // servos hold the spawn positions, at spawn and reset
  // The URDF's root is a `world` link: robot_state_publisher publishes its
  // world -> root itself, so TfMode::kRoot adds nothing.
  bool world_link = false;
  // Link names to their index in `links`, made by ModelRegistry::Add, so
  // that tf's per-joint lookups stay O(1) on a 1000-link model.
  std::unordered_map<std::string, int> link_index;
};

// The tf frame of a link of `model`: its tf prefix and the link's name.
std::string TfFrame(const Model& model, const std::string& link);

// The index of the link named `link_name` in model.links, or -1 (from its
// link_index once the model is registered, by a scan before).
int LinkIndex(const Model& model, const std::string& link_name);

// A frame of a model: the model and one of its links.
struct FrameRef {
  const Model* model = nullptr;
  const io::LinkFrame* link = nullptr;
};

// Models by name, and by body for naming contacts. Not thread-safe: the node
// guards it with the world's mutex.
class ModelRegistry {
 public:
  // Refuses a name in use.
  physics::Status Add(Model model);
  // Returns false for an unknown name.
  bool Remove(const std::string& name);
  const Model* Find(const std::string& name) const;
  const Model* FindByBody(physics::BodyId body) const;
  // A model name (its root link) or '<model>/<link>'; fails naming the
  // unknown model or link.
  physics::Result<FrameRef> ResolveFrame(const std::string& frame) const;
  // '<model>/<link>' of a shape of a body, or "" for a body that is no model.
  std::string ShapeFrame(physics::BodyId body, int shape_index) const;

  const std::map<std::string, Model>& models() const { return models_; }
  std::size_t size() const { return models_.size(); }
  void Clear();

 private:
  static std::uint64_t Key(physics::BodyId body) {
    return (static_cast<std::uint64_t>(body.index) << 32) | body.generation;
  }
  std::map<std::string, Model> models_;  // ordered, so messages list models stably
  std::unordered_map<std::uint64_t, std::string> name_by_body_;
};

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_MODEL_REGISTRY_H_
