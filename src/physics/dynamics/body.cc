#include "rigid_body_sim/physics/body.h"

#include <cmath>
#include <sstream>
#include <string>

#include "physics/dynamics/body_state.h"

namespace rigid_body_sim::physics {
namespace {

constexpr double kUnitQuaternionTolerance = 1e-6;

}  // namespace

std::string FormatVector(const Vec3& v) {
  std::ostringstream out;
  out << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return out.str();
}

// Derived quantities of Baraff's state (Baraff 1997, "Rigid Body
// Simulation I", section 2.11, eqs. (2-40)-(2-42); R from q by section 4):
// v = P / M, R = R(q), I_world^-1 = R I_body^-1 R^T, omega = I_world^-1 L.
void Body::UpdateDerived() {
  if (is_static) {
    linear_velocity.setZero();
    angular_velocity.setZero();
    inverse_inertia_world.setZero();
    return;
  }
  const Mat3 world_from_principal = orientation.toRotationMatrix();
  inverse_inertia_world = world_from_principal * inverse_principal_moments.asDiagonal() *
                          world_from_principal.transpose();
  linear_velocity = inverse_mass * linear_momentum;
  angular_velocity = inverse_inertia_world * angular_momentum;
}

Status ValidateState(const Pose& world_from_body, const Vec3& linear_velocity,
                     const Vec3& angular_velocity) {
  if (!IsFinite(world_from_body.translation)) {
    return Status::Error("position is not finite: " + FormatVector(world_from_body.translation));
  }
  if (!IsFinite(world_from_body.rotation)) {
    return Status::Error("orientation quaternion is not finite");
  }
  const double norm = world_from_body.rotation.norm();
  if (std::abs(norm - 1.0) > kUnitQuaternionTolerance) {
    return Status::Error("orientation quaternion is not unit length (norm " + std::to_string(norm) +
                         ")");
  }
  if (!IsFinite(linear_velocity)) {
    return Status::Error("linear velocity is not finite: " + FormatVector(linear_velocity));
  }
  if (!IsFinite(angular_velocity)) {
    return Status::Error("angular velocity is not finite: " + FormatVector(angular_velocity));
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
  body->pseudo_linear_velocity.setZero();
  body->pseudo_angular_velocity.setZero();
  body->awake = true;
  body->sleep_time = 0.0;
  body->speeding_up_time = 0.0;
  body->UpdateDerived();
  body->start_linear_velocity = body->linear_velocity;
  body->start_angular_momentum = body->angular_momentum;
}

}  // namespace rigid_body_sim::physics
