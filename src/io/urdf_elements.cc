#include "io/urdf_elements.h"

#include <cctype>
#include <cstdlib>

namespace rigid_body_sim::io {

using physics::FormatNumber;
using physics::MassProperties;
using physics::Mat3;
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
      // <mu1>0.5</mu1>, or the older <mu1 value="0.5"/>.
      const char* text = mu->GetText() != nullptr ? mu->GetText() : mu->Attribute("value");
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

std::vector<std::string> FillOmittedProductsOfInertia(TiXmlElement* robot) {
  std::vector<std::string> changed;
  for (TiXmlElement* link = robot->FirstChildElement("link"); link != nullptr;
       link = link->NextSiblingElement("link")) {
    TiXmlElement* inertial = link->FirstChildElement("inertial");
    TiXmlElement* inertia = inertial == nullptr ? nullptr : inertial->FirstChildElement("inertia");
    if (inertia == nullptr || inertia->Attribute("ixx") == nullptr ||
        inertia->Attribute("iyy") == nullptr || inertia->Attribute("izz") == nullptr) {
      continue;
    }
    bool filled = false;
    for (const char* product : {"ixy", "ixz", "iyz"}) {
      if (inertia->Attribute(product) != nullptr) continue;
      inertia->SetAttribute(product, "0");
      filled = true;
    }
    const char* name = link->Attribute("name");
    if (filled) changed.push_back(name == nullptr ? "" : name);
  }
  return changed;
}

namespace {

// Raises the two smaller principal moments of `inertia` by one factor until
// I1 + I2 = I3, if they miss the triangle inequality by at most
// kMaxTriangleDeficit of I3; keeps the principal axes. False when the
// tensor is not positive definite or misses by more.
bool BalanceInertia(Mat3* inertia) {
  const physics::PrincipalAxes axes = physics::ComputePrincipalAxes(*inertia);
  Vec3 moments = axes.principal_moments;
  const double sum = moments[0] + moments[1];
  if (!(moments[0] > 0.0) || sum >= moments[2]) return false;
  if (moments[2] - sum > kMaxTriangleDeficit * moments[2]) return false;
  moments.head<2>() *= moments[2] / sum;
  const Mat3 body_from_principal = axes.body_from_principal.toRotationMatrix();
  *inertia = body_from_principal * moments.asDiagonal() * body_from_principal.transpose();
  return true;
}

}  // namespace

Result<InertialReading> ReadInertial(const urdf::Link& link,
                                     const MassProperties& geometry_in_link) {
  const urdf::Inertial& inertial = *link.inertial;
  const std::string where = "link " + Quoted(link.name);
  InertialReading reading;
  if (inertial.mass == 0.0) {
    reading.warning = where + " has mass 0: it adds no mass (a model without mass is static, " +
                      "an articulation whose base has none is fixed)";
    return reading;
  }
  MassProperties in_inertial_frame;
  in_inertial_frame.mass = inertial.mass;
  in_inertial_frame.inertia_about_com << inertial.ixx, inertial.ixy, inertial.ixz,  //
      inertial.ixy, inertial.iyy, inertial.iyz,                                     //
      inertial.ixz, inertial.iyz, inertial.izz;
  const Pose link_from_inertial = ToPose(inertial.origin);
  if (!link_from_inertial.translation.allFinite() ||
      !physics::IsFinite(link_from_inertial.rotation)) {
    return Result<InertialReading>::Error(where + ": invalid <inertial>: origin is not finite");
  }
  Pose link_from_com = link_from_inertial;
  if (in_inertial_frame.inertia_about_com.isZero(0.0) && geometry_in_link.mass > 0.0) {
    // The geometry's tensor about the stated centre of mass, in the link
    // frame: the stated origin keeps the centre, the geometry the shape.
    in_inertial_frame.inertia_about_com =
        geometry_in_link.inertia_about_com * (inertial.mass / geometry_in_link.mass);
    link_from_com.rotation = Quat::Identity();
    reading.warning = where + " <inertia> is all zero; taken from its collision geometry for " +
                      FormatNumber(inertial.mass) + " kg";
  } else if (BalanceInertia(&in_inertial_frame.inertia_about_com)) {
    reading.warning = where + " <inertia> misses I1 + I2 >= I3 by less than " +
                      FormatNumber(100.0 * kMaxTriangleDeficit) +
                      " %; I1 and I2 raised until it holds";
  }
  if (Status status = physics::ValidateMassProperties(in_inertial_frame); !status.ok()) {
    return Result<InertialReading>::Error(where + ": invalid <inertial>: " + status.message());
  }
  reading.in_link = physics::TransformMassProperties(in_inertial_frame, link_from_com);
  return reading;
}

}  // namespace rigid_body_sim::io
