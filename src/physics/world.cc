#include "rigid_body_sim/physics/world.h"

#include <cassert>
#include <cmath>
#include <sstream>
#include <string>
#include <variant>

#include "rigid_body_sim/physics/integrator.h"

namespace rigid_body_sim::physics {
namespace {

constexpr double kUnitQuaternionTolerance = 1e-6;

std::string Describe(const Vec3& v) {
  std::ostringstream out;
  out << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return out.str();
}

Status ValidateState(const Pose& world_from_body, const Vec3& linear_velocity,
                     const Vec3& angular_velocity) {
  if (!IsFinite(world_from_body.translation)) {
    return Status::Error("position is not finite: " + Describe(world_from_body.translation));
  }
  if (!IsFinite(world_from_body.rotation)) {
    return Status::Error("orientation quaternion is not finite");
  }
  const double norm = world_from_body.rotation.norm();
  if (std::abs(norm - 1.0) > kUnitQuaternionTolerance) {
    return Status::Error("orientation quaternion is not unit length (norm " +
                         std::to_string(norm) + ")");
  }
  if (!IsFinite(linear_velocity)) {
    return Status::Error("linear velocity is not finite: " + Describe(linear_velocity));
  }
  if (!IsFinite(angular_velocity)) {
    return Status::Error("angular velocity is not finite: " + Describe(angular_velocity));
  }
  return Status::Ok();
}

// Sets (x, q, P, L) from the pose of the body frame and the twist of its
// origin: v_com = v_origin + omega x (x_com - p_origin), P = M v_com,
// L = I_world omega.
void SetBodyState(const Pose& world_from_body, const Vec3& linear_velocity,
                  const Vec3& angular_velocity, Body* body) {
  const Pose world_from_principal = world_from_body * body->principal_from_body.Inverse();
  body->position = world_from_principal.translation;
  body->orientation = world_from_principal.rotation.normalized();
  if (body->is_static) {
    body->linear_momentum.setZero();
    body->angular_momentum.setZero();
  } else {
    const Vec3 com_velocity =
        linear_velocity + angular_velocity.cross(body->position - world_from_body.translation);
    body->linear_momentum = body->mass * com_velocity;
    const Mat3 rotation = body->orientation.toRotationMatrix();
    const Vec3 principal_moments = body->inverse_principal_moments.cwiseInverse();
    body->angular_momentum =
        rotation * principal_moments.asDiagonal() * rotation.transpose() * angular_velocity;
  }
  body->force.setZero();
  body->torque.setZero();
  body->step_acceleration.setZero();
  body->UpdateDerived();
}

}  // namespace

Status ValidateWorldSettings(const WorldSettings& settings) {
  if (!IsFinite(settings.gravity)) {
    return Status::Error("gravity is not finite: " + Describe(settings.gravity));
  }
  if (!std::isfinite(settings.time_step) || settings.time_step <= 0.0) {
    return Status::Error("time_step must be positive and finite, got " +
                         std::to_string(settings.time_step));
  }
  return Status::Ok();
}

World::World(const WorldSettings& settings) : settings_(settings) {
  assert(ValidateWorldSettings(settings).ok());
}

Status World::SetSettings(const WorldSettings& settings) {
  Status status = ValidateWorldSettings(settings);
  if (status.ok()) settings_ = settings;
  return status;
}

Result<BodyId> World::CreateBody(const BodyDef& def) {
  if (Status status = ValidateState(def.world_from_body, def.linear_velocity,
                                    def.angular_velocity);
      !status.ok()) {
    return status;
  }
  for (std::size_t i = 0; i < def.shapes.size(); ++i) {
    const ShapeDef& shape = def.shapes[i];
    if (Status status = ValidateShapeDef(shape); !status.ok()) {
      return Status::Error("shape " + std::to_string(i) + ": " + status.message());
    }
    if (std::holds_alternative<HalfSpace>(shape.geometry) && !def.is_static) {
      return Status::Error("shape " + std::to_string(i) +
                           ": a half-space may only belong to a static body");
    }
  }

  Body body;
  body.is_static = def.is_static;
  body.user_data = def.user_data;
  body.shapes = def.shapes;
  if (!def.is_static) {
    if (Status status = ValidateMassProperties(def.mass_properties); !status.ok()) {
      return status;
    }
    const PrincipalAxes axes = ComputePrincipalAxes(def.mass_properties.inertia_about_com);
    body.mass = def.mass_properties.mass;
    body.inverse_mass = 1.0 / body.mass;
    body.inverse_principal_moments = axes.principal_moments.cwiseInverse();
    const Pose body_from_principal{def.mass_properties.center_of_mass, axes.body_from_principal};
    body.principal_from_body = body_from_principal.Inverse();
  }
  SetBodyState(def.world_from_body, def.linear_velocity, def.angular_velocity, &body);
  body.in_use = true;

  BodyId id;
  if (free_slots_.empty()) {
    id.index = static_cast<std::uint32_t>(bodies_.size());
    bodies_.push_back(std::move(body));
  } else {
    id.index = free_slots_.back();
    free_slots_.pop_back();
    body.generation = bodies_[id.index].generation;
    bodies_[id.index] = std::move(body);
  }
  id.generation = bodies_[id.index].generation;
  ++body_count_;
  return id;
}

Status World::DestroyBody(BodyId id) {
  if (!IsValid(id)) return Status::Error("no body with this id");
  Body& body = bodies_[id.index];
  const std::uint32_t next_generation = body.generation + 1;
  body = Body();
  body.generation = next_generation;
  free_slots_.push_back(id.index);
  --body_count_;
  return Status::Ok();
}

bool World::IsValid(BodyId id) const {
  return id.index < bodies_.size() && bodies_[id.index].in_use &&
         bodies_[id.index].generation == id.generation;
}

const Body& World::GetBody(BodyId id) const {
  assert(IsValid(id));
  return bodies_[id.index];
}

Body& World::MutableBody(BodyId id) {
  assert(IsValid(id));
  return bodies_[id.index];
}

Pose World::GetPose(BodyId id) const { return GetBody(id).WorldFromBody(); }

Vec3 World::GetLinearVelocity(BodyId id) const {
  const Body& body = GetBody(id);
  return body.PointVelocity(body.WorldFromBody().translation);
}

Vec3 World::GetAngularVelocity(BodyId id) const { return GetBody(id).angular_velocity; }

Status World::SetState(BodyId id, const Pose& world_from_body, const Vec3& linear_velocity,
                       const Vec3& angular_velocity) {
  if (!IsValid(id)) return Status::Error("no body with this id");
  if (Status status = ValidateState(world_from_body, linear_velocity, angular_velocity);
      !status.ok()) {
    return status;
  }
  SetBodyState(world_from_body, linear_velocity, angular_velocity, &MutableBody(id));
  return Status::Ok();
}

Status World::ApplyForceAtPoint(BodyId id, const Vec3& force_world, const Vec3& point_world) {
  if (!IsValid(id)) return Status::Error("no body with this id");
  if (!IsFinite(force_world)) return Status::Error("force is not finite: " + Describe(force_world));
  if (!IsFinite(point_world)) return Status::Error("point is not finite: " + Describe(point_world));
  Body& body = MutableBody(id);
  if (body.is_static) return Status::Ok();
  body.force += force_world;
  body.torque += (point_world - body.position).cross(force_world);
  return Status::Ok();
}

Status World::ApplyTorque(BodyId id, const Vec3& torque_world) {
  if (!IsValid(id)) return Status::Error("no body with this id");
  if (!IsFinite(torque_world)) {
    return Status::Error("torque is not finite: " + Describe(torque_world));
  }
  Body& body = MutableBody(id);
  if (body.is_static) return Status::Ok();
  body.torque += torque_world;
  return Status::Ok();
}

void World::Step() {
  const double dt = settings_.time_step;
  IntegrateForces(settings_.gravity, dt, &bodies_);
  IntegratePositions(dt, &bodies_);
  time_ += dt;
}

}  // namespace rigid_body_sim::physics
