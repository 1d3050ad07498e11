#include "rigid_body_sim/physics/body.h"

namespace rigid_body_sim::physics {

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

}  // namespace rigid_body_sim::physics
