// The scheme, stated once:
//  * Momenta are kicked by the step's forces first (symplectic Euler), so the
//    contact solver sees and corrects the velocities the step will end with.
//  * Position: the trapezoidal rule x(t+dt) = x + dt/2 (v(t) + v(t+dt)),
//    with v(t) taken after the collision impulses and v(t+dt) after the
//    contact solver. For a free body this is x + dt v + dt^2/2 a: exact for
//    any constant external acceleration such as gravity, unlike plain
//    symplectic Euler whose free-fall error is g t dt / 2. A body that a
//    resting contact pushed during the step has v(t) set to v(t+dt) by the
//    solver stage, i.e. symplectic Euler: it does not sink while held at
//    rest, and momentum exchanged through contacts is conserved exactly.
//  * Orientation: with L fixed over the step, the torque-free Euler equations
//    are integrated for q by RK4. Integrating momenta, not omega, keeps L
//    exactly constant in torque-free flight, so the gyroscopic (Dzhanibekov)
//    motion is kept; RK4 keeps the kinetic energy drift at O(dt^4). A body
//    with isotropic inertia spins at constant omega and is rotated exactly.
//  * q is renormalised after every step.
#include "physics/dynamics/integrator.h"

#include <cassert>
#include <cmath>

namespace rigid_body_sim::physics {
namespace {

// dq/dt = 1/2 (0, omega) q with omega = R(q) I_principal^-1 R(q)^T L
// (Baraff 1997, "Rigid Body Simulation I", section 4, eq. (4-2)).
Eigen::Vector4d QuaternionRate(const Eigen::Vector4d& wxyz, const Vec3& inverse_principal_moments,
                               const Vec3& angular_momentum_world) {
  const Quat q(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  const Quat q_unit = q.normalized();
  const Vec3 angular_momentum_principal = q_unit.conjugate() * angular_momentum_world;
  const Vec3 omega_world =
      q_unit * inverse_principal_moments.cwiseProduct(angular_momentum_principal);
  const Quat omega_quat(0.0, omega_world.x(), omega_world.y(), omega_world.z());
  const Quat rate = omega_quat * q;
  return 0.5 * Eigen::Vector4d(rate.w(), rate.x(), rate.y(), rate.z());
}

}  // namespace

// q turned by the rotation vector theta (|theta| about theta / |theta|),
// exactly: exp(theta / 2) q.
Quat Rotated(const Quat& q, const Vec3& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle == 0.0) return q;
  return (Quat(Eigen::AngleAxisd(angle, rotation_vector / angle)) * q).normalized();
}

Quat DriftOrientation(const Quat& world_from_principal, const Vec3& inverse_principal_moments,
                      const Vec3& start_angular_momentum, const Vec3& end_angular_momentum,
                      double dt) {
  // Isotropic inertia (I = k 1: a sphere, a cube): omega = L / k whatever the
  // orientation. A constant torque changes L linearly over the step, so
  // omega is linear in t; about a fixed axis the turn is then exactly
  // dt (omega_start + omega_end) / 2, the closed form of a spin-up under
  // constant torque. Without torque this is the exact rotation by omega dt.
  if (inverse_principal_moments.x() == inverse_principal_moments.y() &&
      inverse_principal_moments.y() == inverse_principal_moments.z()) {
    const Vec3 mean_momentum = 0.5 * (start_angular_momentum + end_angular_momentum);
    return Rotated(world_from_principal, dt * inverse_principal_moments.x() * mean_momentum);
  }
  // RK4 on q' = 1/2 omega(q, L(t)) q with L(t) linear between the step's
  // ends: fourth order for a constant torque as for none.
  const Vec3 change = end_angular_momentum - start_angular_momentum;
  const Vec3 mid_momentum = start_angular_momentum + 0.5 * change;
  const Eigen::Vector4d q0(world_from_principal.w(), world_from_principal.x(),
                           world_from_principal.y(), world_from_principal.z());
  const Eigen::Vector4d k1 = QuaternionRate(q0, inverse_principal_moments, start_angular_momentum);
  const Eigen::Vector4d k2 =
      QuaternionRate(q0 + 0.5 * dt * k1, inverse_principal_moments, mid_momentum);
  const Eigen::Vector4d k3 =
      QuaternionRate(q0 + 0.5 * dt * k2, inverse_principal_moments, mid_momentum);
  const Eigen::Vector4d k4 =
      QuaternionRate(q0 + dt * k3, inverse_principal_moments, end_angular_momentum);
  const Eigen::Vector4d q1 = q0 + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  return Quat(q1[0], q1[1], q1[2], q1[3]).normalized();
}

Vec3 TurnBetween(const Quat& from, const Quat& to, const Vec3& guess) {
  Eigen::AngleAxisd shortest(to * from.conjugate());
  Vec3 axis = shortest.axis();
  double angle = shortest.angle();  // [0, pi] once the axis is flipped to match
  if (angle > kPi) {
    angle = 2.0 * kPi - angle;
    axis = -axis;
  }
  if (angle == 0.0) {
    // Whole turns only, about the guess's axis.
    const double guess_angle = guess.norm();
    const double turns = std::round(guess_angle / (2.0 * kPi));
    if (guess_angle == 0.0) return Vec3::Zero();
    return Vec3(guess * (turns * 2.0 * kPi / guess_angle));
  }
  // The angle about `axis` that the guess turns, and the whole turns to add
  // so the result lies nearest to it.
  const double along = guess.dot(axis);
  const double turns = std::round((along - angle) / (2.0 * kPi));
  return axis * (angle + turns * 2.0 * kPi);
}

Vec3 AngularMomentumFor(const Body& body, const Vec3& angular_velocity) {
  const Mat3 rotation = body.orientation.toRotationMatrix();
  return rotation * body.inverse_principal_moments.cwiseInverse().asDiagonal() *
         (rotation.transpose() * angular_velocity);
}

void IntegrateForces(const Vec3& gravity, double dt, const std::vector<std::uint32_t>& moving,
                     std::vector<Body>* bodies) {
  assert(dt > 0.0);
  for (const std::uint32_t i : moving) {
    Body& body = (*bodies)[i];
    if (!body.in_use || body.is_static || !body.awake) continue;
    body.start_linear_velocity = body.linear_velocity;
    body.start_angular_momentum = body.angular_momentum;
    body.linear_momentum += (body.mass * gravity + body.force) * dt;
    body.angular_momentum += body.torque * dt;
    body.force.setZero();
    body.torque.setZero();
    body.UpdateDerived();
  }
}

void IntegratePositions(double dt, const std::vector<std::uint32_t>& moving,
                        std::vector<Body>* bodies) {
  for (const std::uint32_t i : moving) {
    Body& body = (*bodies)[i];
    if (!body.in_use || body.is_static || !body.awake) continue;
    body.position += 0.5 * dt * (body.start_linear_velocity + body.linear_velocity) +
                     dt * body.pseudo_linear_velocity;
    if (!body.angular_momentum.isZero(0.0) || !body.start_angular_momentum.isZero(0.0)) {
      body.orientation = DriftOrientation(body.orientation, body.inverse_principal_moments,
                                          body.start_angular_momentum, body.angular_momentum, dt);
    }
    if (!body.pseudo_angular_velocity.isZero(0.0)) {
      // The split-impulse rotation, a small angle applied as an exact rotation.
      body.orientation = Rotated(body.orientation, dt * body.pseudo_angular_velocity);
    }
    body.start_linear_velocity = body.linear_velocity;
    body.start_angular_momentum = body.angular_momentum;
    body.pseudo_linear_velocity.setZero();
    body.pseudo_angular_velocity.setZero();
    body.UpdateDerived();
  }
}

}  // namespace rigid_body_sim::physics
