#include "io/urdf_checks.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
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
    const std::string field = where + " " + name + "=" + Quoted(text);
    if (end == cursor) return Result<std::vector<double>>::Error(field + " is not a number");
    if (!std::isfinite(value) || errno == ERANGE) {
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

// A movable joint's <axis xyz> finite and not the zero vector (urdfdom keeps
// a zero axis, about which the joint could not move; a fixed joint's is
// never used); its <limit> effort and
// velocity >= 0 (0, as many descriptions write it, is no limit) and its
// lower and upper finite; its <dynamics> damping and friction >= 0.
Status CheckJointElements(const TiXmlElement& joint, const std::string& where) {
  constexpr double kLargest = 1e300;
  const char* type = joint.Attribute("type");
  const std::string kind = type == nullptr ? "" : type;
  const bool movable = kind == "revolute" || kind == "continuous" || kind == "prismatic";
  if (const TiXmlElement* axis = joint.FirstChildElement("axis"); axis != nullptr && movable) {
    const std::string at = where + " <axis>";
    Result<std::vector<double>> xyz = NumbersIn(*axis, "xyz", at, 3, -kLargest, kLargest, false);
    if (!xyz.ok()) return xyz.status();
    if (!xyz->empty() && std::all_of(xyz->begin(), xyz->end(), [](double v) { return v == 0.0; })) {
      return Status::Error(at + " xyz='0 0 0' is the zero vector; give the joint's direction");
    }
  }
  const std::pair<const char*, std::pair<const char*, double>> ranges[] = {
      {"limit", {"effort", 0.0}},      {"limit", {"velocity", 0.0}},
      {"limit", {"lower", -kLargest}}, {"limit", {"upper", -kLargest}},
      {"dynamics", {"damping", 0.0}},  {"dynamics", {"friction", 0.0}}};
  for (const auto& [element_name, attribute] : ranges) {
    const TiXmlElement* element = joint.FirstChildElement(element_name);
    if (element == nullptr) continue;
    Result<std::vector<double>> value =
        NumbersIn(*element, attribute.first, where + " <" + element_name + ">", 1, attribute.second,
                  kLargest, false);
    if (!value.ok()) return value.status();
  }
  return Status::Ok();
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

}  // namespace rigid_body_sim::io
