// Articulations of the articulation tests: links, hinges and a world of
// 1/240 s steps under g.
#ifndef RIGID_BODY_SIM_TEST_PHYSICS_ARTICULATION_FIXTURES_H_
#define RIGID_BODY_SIM_TEST_PHYSICS_ARTICULATION_FIXTURES_H_

#include <memory>
#include <string>

#include "scene.h"

namespace rigid_body_sim::physics::testing {

constexpr double kG = 9.81;
constexpr double kDt = 1.0 / 240.0;

// A slender rod of mass m and length l along -z of its link frame, with a
// sphere of radius `radius` at its end for contact.
inline LinkDef Rod(double mass, double length, double radius = 0.0) {
  LinkDef link;
  link.mass_properties.mass = mass;
  link.mass_properties.center_of_mass = Vec3(0, 0, -length);
  const double i = mass * 1e-4;  // nearly a point mass at the end
  link.mass_properties.inertia_about_com = Mat3::Identity() * i;
  if (radius > 0.0) {
    ShapeDef shape;
    shape.geometry = Sphere{radius};
    shape.body_from_shape.translation = Vec3(0, 0, -length);
    link.shapes.push_back(shape);
  }
  return link;
}

inline LinkDef Anchor() {
  LinkDef link;
  link.mass_properties.mass = 1.0;
  link.mass_properties.inertia_about_com = Mat3::Identity() * 0.01;
  return link;
}

// Joint k: revolute about y, at the end of the parent rod of `length`
// (at the base's origin for the first).
inline JointDef Hinge(int child, double parent_length, double position) {
  JointDef joint;
  joint.name = "j" + std::to_string(child);
  joint.type = JointType::kContinuous;
  joint.parent_link = child - 1;
  joint.child_link = child;
  joint.parent_from_joint.translation = Vec3(0, 0, -parent_length);
  joint.axis = Vec3::UnitY();
  joint.position = position;
  return joint;
}

inline World MakeWorld(MotionSolverKind solver = MotionSolverKind::kExact) {
  WorldSettings settings;
  settings.motion_solver = solver;
  settings.time_step = kDt;
  settings.gravity = Vec3(0, 0, -kG);
  return World(settings);
}

// A 0.2 m box with a 5 cm flap on a continuous hinge on its top, its base
// at `base_z`.
inline ArticulationDef BoxWithFlap(double base_z) {
  ArticulationDef def;
  def.world_from_base = Translation(0, 0, base_z);
  LinkDef body;
  body.mass_properties = BoxMassProperties(1000.0, Vec3(0.2, 0.2, 0.2));
  ShapeDef box;
  box.geometry = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3(0.2, 0.2, 0.2)));
  box.material = MakeMaterial(0.8, 0.0);
  body.shapes.push_back(box);
  LinkDef flap;
  flap.mass_properties = BoxMassProperties(1000.0, Vec3(0.05, 0.05, 0.05));
  flap.mass_properties.center_of_mass = Vec3(0, 0, 0.05);
  JointDef hinge;
  hinge.name = "flap";
  hinge.type = JointType::kContinuous;
  hinge.parent_from_joint.translation = Vec3(0, 0, 0.1);
  hinge.axis = Vec3::UnitY();
  def.links = {body, flap};
  def.joints = {hinge};
  return def;
}

// A box link of `mass` and full edge lengths `size`, e = 0.
inline LinkDef BoxLink(double mass, const Vec3& size, double friction) {
  LinkDef link;
  link.mass_properties = BoxMassProperties(mass / size.prod(), size);
  ShapeDef shape;
  shape.geometry = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(size));
  shape.material = MakeMaterial(friction, 0.0);
  link.shapes.push_back(shape);
  return link;
}

// A prismatic joint from `parent` to `child` at `origin`, within +-0.5 m.
inline JointDef Slider(const std::string& name, int parent, int child, const Vec3& origin,
                       const Vec3& axis) {
  JointDef joint;
  joint.name = name;
  joint.type = JointType::kPrismatic;
  joint.parent_link = parent;
  joint.child_link = child;
  joint.parent_from_joint.translation = origin;
  joint.axis = axis;
  joint.lower = -0.5;
  joint.upper = 0.5;
  joint.effort_limit = 1000.0;
  return joint;
}

}  // namespace rigid_body_sim::physics::testing

#endif  // RIGID_BODY_SIM_TEST_PHYSICS_ARTICULATION_FIXTURES_H_
