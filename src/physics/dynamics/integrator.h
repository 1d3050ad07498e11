// Stage 5 of a step: time integration of the bodies' state.
#ifndef RIGID_BODY_SIM_PHYSICS_DYNAMICS_INTEGRATOR_H_
#define RIGID_BODY_SIM_PHYSICS_DYNAMICS_INTEGRATOR_H_

#include <cstdint>
#include <vector>

#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// Where a body is at time t in [0, dt] of the step: the position follows the
// trapezoidal drift exactly (a parabola between the two velocities); the
// orientation turns at a constant rate about one axis from start to end,
// by the rotation vector `turn`, which may exceed half a turn: a small body
// can spin a full turn in one step, where slerp would take the short way
// back.
struct BodyPath {
  Pose start;                           // world_from_principal at t = 0
  Pose end;                             // at t = dt
  Vec3 start_velocity = Vec3::Zero();   // m/s, after the collision impulses
  Vec3 end_velocity = Vec3::Zero();     // m/s
  Vec3 pseudo_velocity = Vec3::Zero();  // m/s
  Vec3 turn = Vec3::Zero();             // rad, world; end.rotation = exp(turn) start.rotation
  double dt = 0.0;                      // s; 0 for a body that does not move
  bool fast = false;                    // sampled along its path
  double reach = 0.0;                   // m, the furthest any point moves

  Pose At(double t) const {
    const double s = t / dt;
    Pose pose;
    pose.translation = start.translation + t * start_velocity +
                       0.5 * t * t / dt * (end_velocity - start_velocity) + t * pseudo_velocity;
    const double angle = turn.norm();
    pose.rotation = angle > 0.0 ? Quat(Eigen::AngleAxisd(s * angle, turn / angle)) * start.rotation
                                : start.rotation;
    return pose;
  }
  Vec3 VelocityAt(double t) const {
    return start_velocity + (t / dt) * (end_velocity - start_velocity);
  }
};

// The rotation vector that turns `from` into `to`, of the winding (the
// number of whole turns added to the shortest angle) closest to `guess`,
// the rotation vector the angular velocity alone would give.
Vec3 TurnBetween(const Quat& from, const Quat& to, const Vec3& guess);

// q turned by the rotation vector theta (|theta| about theta / |theta|),
// exactly: exp(theta / 2) q, normalized; q itself when theta is zero.
Quat Rotated(const Quat& q, const Vec3& rotation_vector);

// L = I_world w, with I_world = R diag(I) R^T at the body's orientation:
// the angular momentum that turns it at `angular_velocity`.
Vec3 AngularMomentumFor(const Body& body, const Vec3& angular_velocity);

// Kick: P += (F + M g) dt and L += tau dt for the awake bodies of `moving`, then
// clears the force and torque accumulators. Records v before the kick for
// the trapezoidal drift.
void IntegrateForces(const Vec3& gravity, double dt, const std::vector<std::uint32_t>& moving,
                     std::vector<Body>* bodies);

// Drift: advances x and q of the awake bodies of `moving` over dt with the
// momenta the step ended with, plus the split-impulse pseudo velocities.
void IntegratePositions(double dt, const std::vector<std::uint32_t>& moving,
                        std::vector<Body>* bodies);

// Orientation after dt with the world angular momentum L going linearly
// from its start to its end value (a constant torque, or none): RK4 on
// q' = 1/2 (0, omega(q, t)) q, omega = R(q) I^-1 R(q)^T L(t); exactly, as a
// rotation by dt times the mean omega, when the three principal moments are
// equal (exact for a torque about a fixed axis).
Quat DriftOrientation(const Quat& world_from_principal, const Vec3& inverse_principal_moments,
                      const Vec3& start_angular_momentum, const Vec3& end_angular_momentum,
                      double dt);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_DYNAMICS_INTEGRATOR_H_
