#include "io/urdf_elements.h"

#include <cctype>
#include <cstdlib>

namespace rigid_body_sim::io {

using physics::FormatNumber;
using physics::MassProperties;
using physics::Pose;
using physics::Quat;
using physics::Result;
using physics::Status;
using physics::Vec3;

Pose ToPose(const urdf::Pose& pose) {
  Quat rotation(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z);
  rotation.normalize();
  return Pose{Vec3(pose.position.x, pose.position.y, pose.position.z), rotation};
}

const char* JointTypeName(int type) {
  switch (type) {
    case urdf::Joint::REVOLUTE:
      return "revolute";
    case urdf::Joint::CONTINUOUS:
      return "continuous";
    case urdf::Joint::PRISMATIC:
      return "prismatic";
    case urdf::Joint::FLOATING:
      return "floating";
    case urdf::Joint::PLANAR:
      return "planar";
    case urdf::Joint::FIXED:
      return "fixed";
    default:
      return "unknown";
  }
}

// Friction coefficients from <gazebo reference="LINK"><mu1>, which urdfdom
// does not read, so the XML is walked directly.
Result<std::map<std::string, double>> ReadGazeboFriction(const TiXmlElement& robot) {
  std::map<std::string, double> friction;
  for (const TiXmlElement* gazebo = robot.FirstChildElement("gazebo"); gazebo != nullptr;
       gazebo = gazebo->NextSiblingElement("gazebo")) {
    const char* reference = gazebo->Attribute("reference");
    if (reference == nullptr) continue;
    for (const TiXmlElement* mu = gazebo->FirstChildElement("mu1"); mu != nullptr;
         mu = mu->NextSiblingElement("mu1")) {
      const char* text = mu->GetText();
      const std::string where = std::string("<gazebo reference=") + Quoted(reference) + "> <mu1>";
      if (text == nullptr) {
        return Result<std::map<std::string, double>>::Error(where + " is empty");
      }
      char* end = nullptr;
      const double value = std::strtod(text, &end);
      while (end != nullptr && std::isspace(static_cast<unsigned char>(*end))) ++end;
      if (end == text || *end != '\0' || !std::isfinite(value) || value < 0.0) {
        return Result<std::map<std::string, double>>::Error(where + " value " + Quoted(text) +
                                                            " is not a finite non-negative number");
      }
      friction[reference] = value;
    }
  }
  return friction;
}

// The link's <inertial> seen in the link frame, after checking it: mass > 0,
// inertia finite, symmetric positive definite and obeying the triangle
// inequality of principal moments.
Result<MassProperties> InertialMassProperties(const urdf::Link& link) {
  const urdf::Inertial& inertial = *link.inertial;
  MassProperties in_inertial_frame;
  in_inertial_frame.mass = inertial.mass;
  in_inertial_frame.inertia_about_com << inertial.ixx, inertial.ixy, inertial.ixz,  //
      inertial.ixy, inertial.iyy, inertial.iyz,                                     //
      inertial.ixz, inertial.iyz, inertial.izz;
  const Pose link_from_inertial = ToPose(inertial.origin);
  const Status status = physics::ValidateMassProperties(in_inertial_frame);
  if (!status.ok() || !link_from_inertial.translation.allFinite() ||
      !physics::IsFinite(link_from_inertial.rotation)) {
    const std::string reason = status.ok() ? "origin is not finite" : status.message();
    return Result<MassProperties>::Error("link " + Quoted(link.name) +
                                         ": invalid <inertial>: " + reason);
  }
  return physics::TransformMassProperties(in_inertial_frame, link_from_inertial);
}

}  // namespace rigid_body_sim::io
