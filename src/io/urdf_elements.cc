#include "io/urdf_elements.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdlib>

#include "rigid_body_sim/io/urdf_loader.h"

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
// does not read, so the XML is walked directly: each a finite number >= 0,
// one above kMaxFrictionCoefficient read as it (see urdf_loader.h).
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
      errno = 0;
      const double value = std::strtod(text, &end);
      const bool out_of_range = errno == ERANGE;
      while (end != nullptr && std::isspace(static_cast<unsigned char>(*end))) ++end;
      if (end == text || *end != '\0' || !std::isfinite(value) || value < 0.0) {
        return Result<std::map<std::string, double>>::Error(where + " value " + Quoted(text) +
                                                            " is not a finite non-negative number");
      }
      // strtod's ERANGE on a finite result: too small for a normal double.
      if (out_of_range) {
        return Result<std::map<std::string, double>>::Error(
            where + " value " + Quoted(text) + " underflows (its magnitude is below " +
            FormatNumber(DBL_MIN) + ", the smallest normal double)");
      }
      friction[reference] = std::min(value, kMaxFrictionCoefficient);
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

// Repairs a tensor with non-negative moments about the axes that is not
// positive definite or misses the triangle inequality I1 + I2 >= I3 of its
// principal moments (CAD exports, sensor frames given 1e-6 everywhere):
// keeping the principal axes, each moment is raised to at least
// kMinMomentRatio of the largest, then I1 and I2 by one factor until
// I1 + I2 = I3, a flat plate's moments, the nearest a rigid body can have.
// Unless `max_deficit` is 1 or more, only a positive definite tensor that
// misses I1 + I2 >= I3 by at most `max_deficit` of I3 is repaired. Returns what was changed, or an
// empty string when nothing was (a valid tensor, or one left for the validation to refuse).
std::string RepairInertia(double max_deficit, Mat3* inertia) {
  constexpr double kMinMomentRatio = 1e-3;
  const physics::PrincipalAxes axes = physics::ComputePrincipalAxes(*inertia);
  const Vec3 before = axes.principal_moments;
  const bool balance_all = max_deficit >= 1.0;
  if (!balance_all &&
      (!(before[0] > 0.0) || before[0] + before[1] < (1.0 - max_deficit) * before[2])) {
    return "";
  }
  Vec3 moments = before;
  const double floor = kMinMomentRatio * moments[2];
  for (int k = 0; k < 2; ++k) moments[k] = std::max(moments[k], floor);
  const double sum = moments[0] + moments[1];
  if (sum < moments[2]) moments.head<2>() *= moments[2] / sum;
  if (moments == before && before[0] > 0.0) return "";
  const Mat3 body_from_principal = axes.body_from_principal.toRotationMatrix();
  *inertia = body_from_principal * moments.asDiagonal() * body_from_principal.transpose();
  const auto list = [](const Vec3& v) {
    return "[" + FormatNumber(v[0]) + ", " + FormatNumber(v[1]) + ", " + FormatNumber(v[2]) + "]";
  };
  const bool definite = before[0] > 0.0;
  return std::string(definite ? "misses I1 + I2 >= I3" : "is not positive definite") +
         ": principal moments " + list(before) + " kg m^2 read as " + list(moments) +
         " (same axes)";
}

}  // namespace

Result<InertialReading> ReadInertial(const urdf::Link& link, const MassProperties& geometry_in_link,
                                     bool balance) {
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
  const Mat3& stated = in_inertial_frame.inertia_about_com;
  // Round-off: entries below a micrometre's lever on the link's mass are
  // read as 0 (iCub's ixx = iyy = -5.4e-20 kg m^2, izz = 0, for 0.526 kg),
  // and a negative moment is refused only beyond it and beyond 1e-9 of the
  // largest.
  const double round_off = 1e-12 * inertial.mass;
  const bool all_zero = stated.cwiseAbs().maxCoeff() <= round_off;
  const double largest = stated.diagonal().cwiseAbs().maxCoeff();
  for (int k = 0; k < 3 && !all_zero; ++k) {
    if (stated(k, k) < -std::max(1e-9 * largest, round_off)) {
      static const char* const kNames[] = {"ixx", "iyy", "izz"};
      return Result<InertialReading>::Error(where + ": invalid <inertial>: " + kNames[k] + " " +
                                            FormatNumber(stated(k, k)) +
                                            " is negative; a moment of inertia is >= 0");
    }
  }
  if (all_zero && geometry_in_link.mass <= 0.0) {
    // No tensor and no geometry to take one from: a ball of water of that
    // mass, 2/5 m r^2, so the link turns as a small solid does.
    const double radius = std::cbrt(3.0 * inertial.mass / (4.0 * physics::kPi * 1000.0));
    in_inertial_frame.inertia_about_com =
        Mat3::Identity() * (0.4 * inertial.mass * radius * radius);
    reading.warning = where + " <inertia> is all zero and it has no collision geometry; taken " +
                      "as a ball of water of " + FormatNumber(inertial.mass) + " kg";
  } else if (all_zero) {
    // The geometry's tensor about the stated centre of mass, in the link
    // frame: the stated origin keeps the centre, the geometry the shape.
    in_inertial_frame.inertia_about_com =
        geometry_in_link.inertia_about_com * (inertial.mass / geometry_in_link.mass);
    link_from_com.rotation = Quat::Identity();
    reading.warning = where + " <inertia> is all zero; taken from its collision geometry for " +
                      FormatNumber(inertial.mass) + " kg";
  } else if (const std::string repaired = RepairInertia(balance ? 1.0 : kMaxTriangleDeficit,
                                                        &in_inertial_frame.inertia_about_com);
             !repaired.empty()) {
    reading.warning = where + " <inertia> " + repaired;
  }
  if (Status status = physics::ValidateMassProperties(in_inertial_frame); !status.ok()) {
    return Result<InertialReading>::Error(where + ": invalid <inertial>: " + status.message() +
                                          " (~balance_inertia repairs it)");
  }
  reading.in_link = physics::TransformMassProperties(in_inertial_frame, link_from_com);
  return reading;
}

}  // namespace rigid_body_sim::io
