// Small scene builders shared by the world-level physics tests.
#ifndef RIGID_BODY_SIM_TEST_PHYSICS_SCENE_H_
#define RIGID_BODY_SIM_TEST_PHYSICS_SCENE_H_

#include <memory>

#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::physics::testing {

inline Material MakeMaterial(double friction, double restitution) {
  Material material;
  material.friction = friction;
  material.restitution = restitution;
  return material;
}

// The static half-space z <= 0 of `world_from_ground`.
inline BodyId AddGround(World* world, const Material& material,
                        const Pose& world_from_ground = Pose::Identity()) {
  BodyDef def;
  def.is_static = true;
  def.world_from_body = world_from_ground;
  ShapeDef shape;
  shape.geometry = HalfSpace{};
  shape.material = material;
  def.shapes.push_back(shape);
  return world->CreateBody(def).value();
}

struct BoxSpec {
  Vec3 size = Vec3::Ones();  // m, full edge lengths
  double mass = 1.0;         // kg
  Pose world_from_body;
  Vec3 linear_velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();
  Material material;
  bool is_static = false;
};

inline BodyId AddBox(World* world, const BoxSpec& spec) {
  BodyDef def;
  def.world_from_body = spec.world_from_body;
  def.linear_velocity = spec.linear_velocity;
  def.angular_velocity = spec.angular_velocity;
  def.is_static = spec.is_static;
  const double volume = spec.size.prod();
  def.mass_properties = BoxMassProperties(spec.mass / volume, spec.size);
  ShapeDef shape;
  shape.geometry = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(spec.size));
  shape.material = spec.material;
  def.shapes.push_back(shape);
  return world->CreateBody(def).value();
}

struct SphereSpec {
  double radius = 0.1;  // m
  double mass = 1.0;    // kg
  Pose world_from_body;
  Vec3 linear_velocity = Vec3::Zero();
  Material material;
};

inline BodyId AddSphere(World* world, const SphereSpec& spec) {
  BodyDef def;
  def.world_from_body = spec.world_from_body;
  def.linear_velocity = spec.linear_velocity;
  const double volume = 4.0 / 3.0 * M_PI * spec.radius * spec.radius * spec.radius;
  def.mass_properties = SphereMassProperties(spec.mass / volume, spec.radius);
  ShapeDef shape;
  shape.geometry = Sphere{spec.radius};
  shape.material = spec.material;
  def.shapes.push_back(shape);
  return world->CreateBody(def).value();
}

inline Pose Translation(double x, double y, double z) {
  Pose pose;
  pose.translation = Vec3(x, y, z);
  return pose;
}

inline double KineticEnergy(const Body& body) {
  if (body.is_static) return 0.0;
  return 0.5 * body.linear_velocity.dot(body.linear_momentum) +
         0.5 * body.angular_velocity.dot(body.angular_momentum);
}

// The normal force between bodies x and y, summed over their reports, N.
inline double NormalForceBetween(const World& world, BodyId x, BodyId y) {
  double total = 0.0;
  for (const ContactReport& report : world.contacts()) {
    if ((report.body_a == x && report.body_b == y) || (report.body_a == y && report.body_b == x)) {
      total += report.normal_force;
    }
  }
  return total;
}

}  // namespace rigid_body_sim::physics::testing

#endif  // RIGID_BODY_SIM_TEST_PHYSICS_SCENE_H_
