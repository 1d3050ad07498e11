// Stage 5 of a step: time integration of the bodies' state.
#ifndef RIGID_BODY_SIM_PHYSICS_INTEGRATOR_H_
#define RIGID_BODY_SIM_PHYSICS_INTEGRATOR_H_

#include <cstdint>
#include <vector>

#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// Kick: P += (F + M g) dt and L += tau dt for the awake bodies of `moving`, then
// clears the force and torque accumulators. Records v before the kick for
// the trapezoidal drift.
void IntegrateForces(const Vec3& gravity, double dt, const std::vector<std::uint32_t>& moving,
                     std::vector<Body>* bodies);

// Drift: advances x and q of the awake bodies of `moving` over dt with the
// momenta the step ended with, plus the split-impulse pseudo velocities.
void IntegratePositions(double dt, const std::vector<std::uint32_t>& moving,
                        std::vector<Body>* bodies);

// Orientation after dt of torque-free motion with world angular momentum L
// held constant: RK4 on q' = 1/2 (0, omega(q)) q, omega(q) = R(q) I^-1 R(q)^T L;
// exactly, as a rotation by the constant omega = I^-1 L, when the three
// principal moments are equal.
Quat DriftOrientation(const Quat& world_from_principal, const Vec3& inverse_principal_moments,
                      const Vec3& angular_momentum_world, double dt);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_INTEGRATOR_H_
