// Articulated bodies: trees of rigid links joined by revolute, continuous and
// prismatic joints, simulated in reduced (joint) coordinates so that no joint
// can stretch or drift (docs/design.md, "Articulated bodies").
#ifndef RIGID_BODY_SIM_PHYSICS_ARTICULATION_H_
#define RIGID_BODY_SIM_PHYSICS_ARTICULATION_H_

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

enum class JointType : std::uint8_t {
  kRevolute,    // turns about the axis, with limits
  kContinuous,  // turns about the axis, no limits
  kPrismatic,   // slides along the axis, with limits
};

// One movable joint between a parent link and a child link, as in URDF: the
// child link frame is the joint frame moved by the joint (turned about or
// slid along `axis`). Rad and N m for turning joints, m and N for prismatic.
struct JointDef {
  std::string name;
  JointType type = JointType::kRevolute;
  int parent_link = 0;        // index into ArticulationDef::links, < child_link
  int child_link = 1;         // each link but the base is the child of one joint
  Pose parent_from_joint;     // the joint frame in the parent link frame (<origin>)
  Vec3 axis = Vec3::UnitX();  // unit, joint frame
  double lower = -std::numeric_limits<double>::infinity();  // rad or m; revolute, prismatic
  double upper = std::numeric_limits<double>::infinity();
  double effort_limit = std::numeric_limits<double>::infinity();    // N m or N, > 0
  double velocity_limit = std::numeric_limits<double>::infinity();  // rad/s or m/s, > 0
  double damping = 0.0;   // N m s/rad or N s/m, >= 0: torque -damping * velocity
  double friction = 0.0;  // N m or N, >= 0: Coulomb friction in the joint
  // Index of the joint this one mimics (one that mimics none), or -1:
  // position = multiplier * leader + offset, so it adds no degree of freedom.
  int mimic_joint = -1;
  double mimic_multiplier = 1.0;
  double mimic_offset = 0.0;  // rad or m
  double position = 0.0;      // rad or m, initial
  double velocity = 0.0;      // rad/s or m/s, initial
};

struct LinkDef {
  std::string name;
  MassProperties mass_properties;  // link frame; validated
  std::vector<ShapeDef> shapes;    // link frame
};

struct ArticulationDef {
  // links[0] is the base. A fixed base stays at world_from_base; a floating
  // one moves freely, starting with the base link's velocity below.
  std::vector<LinkDef> links;
  std::vector<JointDef> joints;  // links.size() - 1 of them, parents before children
  Pose world_from_base;
  bool fixed_base = false;
  Vec3 base_linear_velocity = Vec3::Zero();   // m/s, world, of the base link frame's origin
  Vec3 base_angular_velocity = Vec3::Zero();  // rad/s, world
  // Links of the articulation collide with each other (never two links
  // joined by one joint); off by default, like Gazebo's <self_collide>.
  bool self_collide = false;
  std::uint64_t user_data = 0;  // given to every link body
};

struct ArticulationId {
  static constexpr std::uint32_t kInvalidIndex = std::numeric_limits<std::uint32_t>::max();
  std::uint32_t index = kInvalidIndex;
  std::uint32_t generation = 0;
  bool IsValid() const { return index != kInvalidIndex; }
};

// What drives a joint over the next steps, until replaced.
enum class JointCommandMode : std::uint8_t {
  kNone,      // limp (damping and friction still act)
  kPosition,  // a servo to `position` (and `velocity`), force capped at the effort limit
  kVelocity,  // a motor to `velocity`, force capped at the effort limit
  kEffort,    // `effort`, clamped to the effort limit
};

struct JointCommand {
  JointCommandMode mode = JointCommandMode::kNone;
  double position = 0.0;  // rad or m
  double velocity = 0.0;  // rad/s or m/s; the servo's feed-forward velocity
  double effort = 0.0;    // N m or N
  // N m or N, >= 0: kVelocity's own force cap below the effort limit (a
  // motor's torque, e.g. a differential drive's wheelTorque); 0 or inf: the
  // effort limit alone.
  double max_effort = 0.0;
};

// The position servo: a spring of `stiffness` and a damper of `damping`
// solved implicitly with the contacts (a soft constraint), so it is stable
// at any gain.
struct ServoGains {
  double stiffness = 1e5;  // N m/rad or N/m, > 0
  double damping = 1e3;    // N m s/rad or N s/m, >= 0
};

// A joint's state: position, velocity, and the effort the joint transmitted
// in the last step (command, servo or motor, limits, friction and damping).
struct JointState {
  double position = 0.0;  // rad or m
  double velocity = 0.0;  // rad/s or m/s
  double effort = 0.0;    // N m or N
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_ARTICULATION_H_
