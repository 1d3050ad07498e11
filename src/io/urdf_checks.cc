#include "io/urdf_checks.h"

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace rigid_body_sim::io {
namespace {

using physics::FormatNumber;
using physics::Result;
using physics::Status;
using physics::Vec3;

std::string Quoted(const std::string& text) { return "'" + text + "'"; }

std::string Range(double low, double high) {
  return "[" + FormatNumber(low) + ", " + FormatNumber(high) + "]";
}

// The whitespace-separated numbers of attribute `name` of `element`;
// `where` names the element. A missing attribute gives no numbers.
Result<std::vector<double>> Numbers(const TiXmlElement& element, const char* name,
                                    const std::string& where) {
  const char* text = element.Attribute(name);
  std::vector<double> numbers;
  if (text == nullptr) return numbers;
  const char* cursor = text;
  for (;;) {
    while (*cursor == ' ' || *cursor == '\t' || *cursor == '\n' || *cursor == '\r') ++cursor;
    if (*cursor == '\0') break;
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(cursor, &end);
    const bool out_of_range = errno == ERANGE;
    const std::string field = where + " " + name + "=" + Quoted(text);
    if (end == cursor) {
      const std::string value = text;
      const bool xacro =
          value.find("${") != std::string::npos || value.find("$(") != std::string::npos;
      return Result<std::vector<double>>::Error(
          field + " is not a number" +
          (xacro ? " (an unexpanded xacro expression: the description is xacro without the xacro "
                   "namespace; declare xmlns:xacro or expand it with xacro)"
                 : ""));
    }
    const std::string number(cursor, static_cast<std::size_t>(end - cursor));
    // strtod flags a result too small for a normal double (a subnormal, or
    // 0) as ERANGE too: it is finite, but not the number written.
    if (out_of_range && std::abs(value) <= DBL_MIN) {
      return Result<std::vector<double>>::Error(
          field + ": " + number + " underflows (its magnitude is below " + FormatNumber(DBL_MIN) +
          ", the smallest normal double)");
    }
    if (out_of_range) {
      return Result<std::vector<double>>::Error(field + " is not a finite number: " + number +
                                                " overflows (its magnitude is above " +
                                                FormatNumber(DBL_MAX) + ", the largest double)");
    }
    if (!std::isfinite(value)) {
      return Result<std::vector<double>>::Error(field + " is not a finite number");
    }
    numbers.push_back(value);
    cursor = end;
  }
  return numbers;
}

// Attribute `name` as exactly `count` numbers within [low, high]; absent is
// fine when `required` is false.
Result<std::vector<double>> NumbersIn(const TiXmlElement& element, const char* name,
                                      const std::string& where, std::size_t count, double low,
                                      double high, bool required) {
  Result<std::vector<double>> numbers = Numbers(element, name, where);
  if (!numbers.ok()) return numbers;
  const std::string field = where + " " + name;
  if (numbers->empty() && !required) return numbers;
  if (numbers->size() != count) {
    return Result<std::vector<double>>::Error(field + " must have " + std::to_string(count) +
                                              " number" + (count == 1 ? "" : "s") + ", has " +
                                              std::to_string(numbers->size()));
  }
  for (const double value : *numbers) {
    if (!(value >= low && value <= high)) {
      return Result<std::vector<double>>::Error(
          field + " " + FormatNumber(value) + " is outside the allowed range " + Range(low, high));
    }
  }
  return numbers;
}

// <origin xyz rpy>: xyz within kMaxShapeSize of the parent frame, rpy finite.
Status CheckOrigin(const TiXmlElement& parent, const std::string& where) {
  const TiXmlElement* origin = parent.FirstChildElement("origin");
  if (origin == nullptr) return Status::Ok();
  const std::string at = where + " <origin>";
  Result<std::vector<double>> xyz =
      NumbersIn(*origin, "xyz", at, 3, -kMaxShapeSize, kMaxShapeSize, false);
  if (!xyz.ok()) return xyz.status();
  Result<std::vector<double>> rpy = NumbersIn(*origin, "rpy", at, 3, -1e6, 1e6, false);
  return rpy.status();
}

// The bound of joint numbers that need only be finite: an effort,
// velocity or damping this large is no limit in effect, and the loader
// reads neither <safety_controller> nor <calibration>.
constexpr double kLargestJointNumber = 1e300;

// Whether `text` begins, after blanks, with something strtod reads as a
// number.
bool StartsWithNumber(const char* text) {
  char* end = nullptr;
  std::strtod(text, &end);
  return end != text;
}

// One number of a joint element and its allowed range.
struct JointNumber {
  const char* element;
  const char* attribute;
  double low;
  double high;
};

// The numbers of a joint's <limit>, <dynamics>, <mimic>,
// <safety_controller> and <calibration>, each within its range:
// - <limit> effort and velocity >= 0 (0, as many descriptions write it, is
//   no limit); lower and upper finite, and for a revolute or prismatic
//   (`bounded`) joint reaching within kMaxJointPosition: it starts at 0
//   brought within them, and the node sets no position beyond. A bound
//   beyond it outwards is kept (descriptions for Gazebo write +/-1e16 for
//   "unlimited"), and lower > upper is read as no limit (Bullet's habit;
//   see JointMotion);
// - <dynamics> damping and friction >= 0;
// - <mimic> |multiplier| <= kMaxMimicMultiplier, |offset| <=
//   kMaxJointPosition (CheckMimicJoints checks them with the leader's
//   limits);
// - <safety_controller> and <calibration> finite, k_position and
//   k_velocity >= 0. A calibration that is not a number at all is left to
//   urdfdom, which refuses it by name.
Status CheckJointNumbers(const TiXmlElement& joint, const std::string& where, bool bounded) {
  constexpr double kLargest = kLargestJointNumber;
  const JointNumber numbers[] = {
      {"limit", "effort", 0.0, kLargest},
      {"limit", "velocity", 0.0, kLargest},
      {"limit", "lower", -kLargest, bounded ? kMaxJointPosition : kLargest},
      {"limit", "upper", bounded ? -kMaxJointPosition : -kLargest, kLargest},
      {"dynamics", "damping", 0.0, kLargest},
      {"dynamics", "friction", 0.0, kLargest},
      {"mimic", "multiplier", -kMaxMimicMultiplier, kMaxMimicMultiplier},
      {"mimic", "offset", -kMaxJointPosition, kMaxJointPosition},
      {"safety_controller", "soft_lower_limit", -kLargest, kLargest},
      {"safety_controller", "soft_upper_limit", -kLargest, kLargest},
      {"safety_controller", "k_position", 0.0, kLargest},
      {"safety_controller", "k_velocity", 0.0, kLargest},
      {"calibration", "rising", -kLargest, kLargest},
      {"calibration", "falling", -kLargest, kLargest}};
  for (const JointNumber& number : numbers) {
    const TiXmlElement* element = joint.FirstChildElement(number.element);
    if (element == nullptr) continue;
    const char* text = element->Attribute(number.attribute);
    if (text != nullptr && std::string(number.element) == "calibration" &&
        !StartsWithNumber(text)) {
      continue;
    }
    Result<std::vector<double>> value =
        NumbersIn(*element, number.attribute, where + " <" + number.element + ">", 1, number.low,
                  number.high, false);
    if (!value.ok()) return value.status();
  }
  return Status::Ok();
}

// A movable joint's <axis xyz> finite and not the zero vector (urdfdom keeps
// a zero axis, about which the joint could not move; a fixed joint's is
// never used); then the numbers of its other elements, each within its
// range (CheckJointNumbers).
Status CheckJointElements(const TiXmlElement& joint, const std::string& where) {
  const char* type = joint.Attribute("type");
  const std::string kind = type == nullptr ? "" : type;
  const bool movable = kind == "revolute" || kind == "continuous" || kind == "prismatic";
  if (const TiXmlElement* axis = joint.FirstChildElement("axis"); axis != nullptr && movable) {
    const std::string at = where + " <axis>";
    Result<std::vector<double>> xyz =
        NumbersIn(*axis, "xyz", at, 3, -kLargestJointNumber, kLargestJointNumber, false);
    if (!xyz.ok()) return xyz.status();
    if (!xyz->empty() && std::all_of(xyz->begin(), xyz->end(), [](double v) { return v == 0.0; })) {
      return Status::Error(at + " xyz='0 0 0' is the zero vector; give the joint's direction");
    }
  }
  return CheckJointNumbers(joint, where, kind == "revolute" || kind == "prismatic");
}

Status CheckGeometry(const TiXmlElement& geometry, const std::string& where,
                     double max_aspect_ratio) {
  for (const TiXmlElement* shape = geometry.FirstChildElement(); shape != nullptr;
       shape = shape->NextSiblingElement()) {
    const std::string kind = shape->ValueStr();
    const std::string at = where + " <" + kind + ">";
    if (kind == "box") {
      Result<std::vector<double>> size =
          NumbersIn(*shape, "size", at, 3, kMinShapeSize, kMaxShapeSize, true);
      if (!size.ok()) return size.status();
      if (Status status =
              CheckShapeExtents(Vec3((*size)[0], (*size)[1], (*size)[2]), at, max_aspect_ratio);
          !status.ok()) {
        return status;
      }
    } else if (kind == "cylinder") {
      Result<std::vector<double>> radius =
          NumbersIn(*shape, "radius", at, 1, kMinShapeSize, kMaxShapeSize, true);
      if (!radius.ok()) return radius.status();
      Result<std::vector<double>> length =
          NumbersIn(*shape, "length", at, 1, kMinShapeSize, kMaxShapeSize, true);
      if (!length.ok()) return length.status();
      const double diameter = 2.0 * (*radius)[0];
      if (Status status =
              CheckShapeExtents(Vec3(diameter, diameter, (*length)[0]), at, max_aspect_ratio);
          !status.ok()) {
        return status;
      }
    } else if (kind == "sphere") {
      Result<std::vector<double>> radius =
          NumbersIn(*shape, "radius", at, 1, kMinShapeSize, kMaxShapeSize, true);
      if (!radius.ok()) return radius.status();
    } else if (kind == "mesh") {
      // The hull's own extents are checked once it is built.
      Result<std::vector<double>> scale =
          NumbersIn(*shape, "scale", at, 3, -kMaxShapeSize, kMaxShapeSize, false);
      if (!scale.ok()) return scale.status();
    } else {
      // urdfdom drops such a collision without a word, and the model would
      // fall through the floor where it was meant to touch.
      return Status::Error(at + " is not a URDF collision geometry: use <box>, <cylinder>, " +
                           "<sphere> or <mesh>" +
                           (kind == "capsule" ? " (a capsule is a <cylinder> with a <sphere> "
                                                "at each end, as three <collision>s)"
                                              : ""));
    }
  }
  if (geometry.FirstChildElement() == nullptr) {
    return Status::Error(where + " <geometry> is empty: it needs a <box>, <cylinder>, " +
                         "<sphere> or <mesh>");
  }
  return Status::Ok();
}

Status CheckInertial(const TiXmlElement& inertial, const std::string& where) {
  const std::string at = where + ": invalid <inertial>:";
  if (Status status = CheckOrigin(inertial, at); !status.ok()) return status;
  if (const TiXmlElement* mass = inertial.FirstChildElement("mass"); mass != nullptr) {
    Result<std::vector<double>> value =
        NumbersIn(*mass, "value", at + " <mass>", 1, 0.0, 1e12, true);
    if (!value.ok()) return value.status();
  }
  if (const TiXmlElement* inertia = inertial.FirstChildElement("inertia"); inertia != nullptr) {
    for (const char* name : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}) {
      Result<std::vector<double>> value =
          NumbersIn(*inertia, name, at + " <inertia>", 1, -1e20, 1e20, false);
      if (!value.ok()) return value.status();
    }
  }
  return Status::Ok();
}

Status CheckLink(const TiXmlElement& link, double max_aspect_ratio) {
  const char* name = link.Attribute("name");
  const std::string where = "link " + Quoted(name == nullptr ? "" : name);
  int index = 0;
  for (const TiXmlElement* collision = link.FirstChildElement("collision"); collision != nullptr;
       collision = collision->NextSiblingElement("collision"), ++index) {
    const char* collision_name = collision->Attribute("name");
    const std::string at =
        where + " <collision> " +
        (collision_name == nullptr || *collision_name == '\0' ? std::to_string(index)
                                                              : Quoted(collision_name));
    if (Status status = CheckOrigin(*collision, at); !status.ok()) return status;
    if (const TiXmlElement* geometry = collision->FirstChildElement("geometry");
        geometry != nullptr) {
      if (Status status = CheckGeometry(*geometry, at, max_aspect_ratio); !status.ok()) {
        return status;
      }
    }
  }
  if (const TiXmlElement* inertial = link.FirstChildElement("inertial"); inertial != nullptr) {
    return CheckInertial(*inertial, where);
  }
  return Status::Ok();
}

}  // namespace

Status CheckShapeExtents(const Vec3& extents, const std::string& what, double max_aspect_ratio) {
  for (int axis = 0; axis < 3; ++axis) {
    const double size = extents[axis];
    if (!(size >= kMinShapeSize && size <= kMaxShapeSize)) {
      return Status::Error(what + ": size " + FormatNumber(size) + " m along " + "xyz"[axis] +
                           " is outside the allowed range " + Range(kMinShapeSize, kMaxShapeSize) +
                           " m");
    }
  }
  const double ratio = extents.maxCoeff() / extents.minCoeff();
  if (!(ratio <= max_aspect_ratio)) {
    return Status::Error(what + ": aspect ratio " + FormatNumber(ratio) +
                         " (largest / smallest size) is above the allowed " +
                         FormatNumber(max_aspect_ratio));
  }
  return Status::Ok();
}

namespace {

// The joints must form a tree over the links: no joint from a link to
// itself, no link with two parent joints, no cycle. urdfdom refuses these
// too, but only after linking its link and joint objects to each other by
// shared pointers, which then keep one another alive: a refused model would
// leak inside the node (urdf_loader_fuzzer found it). Following each link's
// one parent upwards, a walk that meets a link of its own walk is a cycle.
Status CheckJointTree(const TiXmlElement& robot) {
  std::map<std::string, std::pair<std::string, std::string>> parent_of;  // child: joint, parent
  for (const TiXmlElement* joint = robot.FirstChildElement("joint"); joint != nullptr;
       joint = joint->NextSiblingElement("joint")) {
    const char* name = joint->Attribute("name");
    const TiXmlElement* parent = joint->FirstChildElement("parent");
    const TiXmlElement* child = joint->FirstChildElement("child");
    const char* parent_link = parent == nullptr ? nullptr : parent->Attribute("link");
    const char* child_link = child == nullptr ? nullptr : child->Attribute("link");
    if (name == nullptr || parent_link == nullptr || child_link == nullptr) continue;
    if (std::string(parent_link) == child_link) {
      return Status::Error("joint " + Quoted(name) + " joins link " + Quoted(child_link) +
                           " to itself");
    }
    const auto [existing, added] = parent_of.emplace(child_link, std::make_pair(name, parent_link));
    if (!added) {
      return Status::Error("link " + Quoted(child_link) + " is the child of two joints, " +
                           Quoted(existing->second.first) + " and " + Quoted(name));
    }
  }
  std::map<std::string, int> walk_of;  // link: the walk that visited it first
  int walk = 0;
  for (const auto& [start, unused] : parent_of) {
    ++walk;
    std::string link = start;
    while (true) {
      const auto [visited, first_visit] = walk_of.emplace(link, walk);
      if (!first_visit) {
        if (visited->second == walk) {
          return Status::Error("the joints form a cycle through link " + Quoted(link));
        }
        break;  // reached a link an earlier walk has checked
      }
      const auto parent = parent_of.find(link);
      if (parent == parent_of.end()) break;
      link = parent->second.second;
    }
  }
  return Status::Ok();
}

}  // namespace

double MaxAspectRatio(bool static_model) {
  return static_model ? kMaxShapeSize / kMinShapeSize : kMaxShapeAspectRatio;
}

bool EveryLinkIsMassless(const TiXmlElement& robot) {
  bool any = false;
  for (const TiXmlElement* link = robot.FirstChildElement("link"); link != nullptr;
       link = link->NextSiblingElement("link")) {
    const char* name = link->Attribute("name");
    if (name != nullptr && std::string(name) == "world") continue;
    const TiXmlElement* inertial = link->FirstChildElement("inertial");
    const TiXmlElement* mass = inertial == nullptr ? nullptr : inertial->FirstChildElement("mass");
    double value = 1.0;
    if (mass == nullptr || mass->QueryDoubleAttribute("value", &value) != TIXML_SUCCESS ||
        value != 0.0) {
      return false;
    }
    any = true;
  }
  return any;
}

bool IsStaticDocument(const TiXmlElement& robot, const UrdfLoadOptions& options) {
  if (options.spawn_static || EveryLinkIsMassless(robot)) return true;
  for (const TiXmlElement* joint = robot.FirstChildElement("joint"); joint != nullptr;
       joint = joint->NextSiblingElement("joint")) {
    const char* type = joint->Attribute("type");
    const TiXmlElement* parent = joint->FirstChildElement("parent");
    const char* parent_link = parent == nullptr ? nullptr : parent->Attribute("link");
    if (type != nullptr && parent_link != nullptr && std::string(type) == "fixed" &&
        std::string(parent_link) == "world") {
      return true;
    }
  }
  return false;
}

// The movable joints of a model that will move as an articulation (not
// welded, not all massless): its step costs about n^3
// in them (docs/limits.md), so their count is a limit of its own.
Status CheckMovableJointCount(const TiXmlElement& robot, const UrdfLoadOptions& options) {
  // Spawned static, an articulated model keeps its joints (its base is
  // fixed), so only welding or having no mass at all exempts it.
  if (!options.articulate || options.weld_movable_joints || EveryLinkIsMassless(robot)) {
    return Status::Ok();
  }
  int movable = 0;
  for (const TiXmlElement* joint = robot.FirstChildElement("joint"); joint != nullptr;
       joint = joint->NextSiblingElement("joint")) {
    const char* type = joint->Attribute("type");
    const std::string kind = type == nullptr ? "" : type;
    if (kind == "revolute" || kind == "continuous" || kind == "prismatic") ++movable;
  }
  if (movable > options.max_joints) {
    return Status::Error("the model has " + std::to_string(movable) +
                         " movable joints, above max_joints_per_model " +
                         std::to_string(options.max_joints));
  }
  return Status::Ok();
}

Status CheckUrdfDocument(const TiXmlElement& robot, const UrdfLoadOptions& options) {
  const double max_aspect_ratio = MaxAspectRatio(IsStaticDocument(robot, options));
  int links = 0;
  for (const TiXmlElement* link = robot.FirstChildElement("link"); link != nullptr;
       link = link->NextSiblingElement("link")) {
    ++links;
  }
  if (links > options.max_links) {
    return Status::Error("the model has " + std::to_string(links) +
                         " links, above max_links_per_model " + std::to_string(options.max_links));
  }
  if (Status status = CheckMovableJointCount(robot, options); !status.ok()) return status;
  for (const TiXmlElement* link = robot.FirstChildElement("link"); link != nullptr;
       link = link->NextSiblingElement("link")) {
    if (Status status = CheckLink(*link, max_aspect_ratio); !status.ok()) return status;
  }
  for (const TiXmlElement* joint = robot.FirstChildElement("joint"); joint != nullptr;
       joint = joint->NextSiblingElement("joint")) {
    const char* name = joint->Attribute("name");
    const std::string where = "joint " + Quoted(name == nullptr ? "" : name);
    for (const Status& status : {CheckOrigin(*joint, where), CheckJointElements(*joint, where)}) {
      if (!status.ok()) return status;
    }
  }
  return CheckJointTree(robot);
}

namespace {

bool IsMovable(int type) {
  return type == urdf::Joint::REVOLUTE || type == urdf::Joint::CONTINUOUS ||
         type == urdf::Joint::PRISMATIC;
}

const char* PositionUnit(int type) { return type == urdf::Joint::PRISMATIC ? "m" : "rad"; }

// The leader's position range as its mimics see it: its <limit> lower and
// upper, a side without one infinite (continuous, lower > upper, or a bound
// beyond kMaxJointPosition, which only the simulation, never a request,
// can drive the joint past).
std::pair<double, double> LeaderRange(const urdf::Joint& leader) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  if (leader.type == urdf::Joint::CONTINUOUS || leader.limits == nullptr ||
      leader.limits->lower > leader.limits->upper) {
    return {-kInfinity, kInfinity};
  }
  const double lower = leader.limits->lower;
  const double upper = leader.limits->upper;
  return {lower >= -kMaxJointPosition ? lower : -kInfinity,
          upper <= kMaxJointPosition ? upper : kInfinity};
}

// A mimic's position over its leader's range and its speed at its leader's
// velocity limit; with a leader unbounded on a side only its multiplier and
// offset are bounded (CheckJointNumbers).
Status CheckMimicWithLeader(const urdf::Joint& joint, const urdf::Joint& leader) {
  const double multiplier = joint.mimic->multiplier;
  const double offset = joint.mimic->offset;
  const std::string where = "joint " + Quoted(joint.name) + " <mimic>";
  const std::string unit = PositionUnit(joint.type);
  const auto [lower, upper] = LeaderRange(leader);
  if (multiplier != 0.0 && std::isfinite(lower) && std::isfinite(upper)) {
    const double from = multiplier * lower + offset;
    const double to = multiplier * upper + offset;
    if (!(std::max(std::abs(from), std::abs(to)) <= kMaxJointPosition)) {
      return Status::Error(
          where + " position range " + Range(std::min(from, to), std::max(from, to)) + " " + unit +
          " (multiplier " + FormatNumber(multiplier) + " times leader " + Quoted(leader.name) +
          " limits " + Range(lower, upper) + ", plus offset " + FormatNumber(offset) +
          ") is outside the allowed range " + Range(-kMaxJointPosition, kMaxJointPosition));
    }
  }
  // A stated velocity limit of 0 is none (JointMotion), and so is the mimic's.
  if (leader.limits != nullptr && leader.limits->velocity > 0.0) {
    const double speed = std::abs(multiplier) * leader.limits->velocity;
    if (!(speed <= kMaxJointSpeed)) {
      return Status::Error(where + " velocity bound " + FormatNumber(speed) + " " + unit +
                           "/s (|multiplier| " + FormatNumber(std::abs(multiplier)) +
                           " times leader " + Quoted(leader.name) + " velocity limit " +
                           FormatNumber(leader.limits->velocity) +
                           ") is outside the allowed range " + Range(0.0, kMaxJointSpeed));
    }
  }
  return Status::Ok();
}

}  // namespace

Status CheckMimicJoints(const urdf::ModelInterface& model) {
  // Leader: 1 + the sum of its mimics' squared multipliers, the factor on
  // its effort limit when it and each mimic exert it (physics::MakeModel).
  std::map<std::string, double> effort_scale;
  for (const auto& [name, joint] : model.joints_) {
    if (joint->mimic == nullptr || !IsMovable(joint->type)) continue;
    const auto found = model.joints_.find(joint->mimic->joint_name);
    if (found == model.joints_.end()) continue;  // CheckJoints names it
    const urdf::Joint& leader = *found->second;
    if (Status status = CheckMimicWithLeader(*joint, leader); !status.ok()) return status;
    double& scale = effort_scale.emplace(leader.name, 1.0).first->second;
    scale += joint->mimic->multiplier * joint->mimic->multiplier;
    // An effort limit of 0 is none, and infinite by design.
    const double effort = leader.limits == nullptr ? 0.0 : leader.limits->effort;
    if (effort > 0.0 && !std::isfinite(scale * effort)) {
      return Status::Error(
          "joint " + Quoted(name) + " <mimic> multiplier " +
          FormatNumber(joint->mimic->multiplier) + " raises the effort scale of leader " +
          Quoted(leader.name) + " (1 + its mimics' squared multipliers) to " + FormatNumber(scale) +
          ", and its effort limit " + FormatNumber(effort) + " times that is not finite");
    }
  }
  return Status::Ok();
}

std::vector<std::string> IgnoredElements(const TiXmlElement& robot) {
  std::vector<std::string> ignored;
  const auto attribute = [](const TiXmlElement& element, const char* name) {
    const char* value = element.Attribute(name);
    return std::string(value == nullptr ? "" : value);
  };
  for (const TiXmlElement* transmission = robot.FirstChildElement("transmission");
       transmission != nullptr; transmission = transmission->NextSiblingElement("transmission")) {
    ignored.push_back("<transmission " + Quoted(attribute(*transmission, "name")) + ">");
  }
  // Once each: descriptions repeat a transmission per hardware interface
  // (Franka's gives every joint three of the same name).
  std::vector<std::string> unique;
  for (std::string& element : ignored) {
    if (std::find(unique.begin(), unique.end(), element) == unique.end()) {
      unique.push_back(std::move(element));
    }
  }
  return unique;
}

}  // namespace rigid_body_sim::io
