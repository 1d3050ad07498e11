// What every contact row shares, a body's or a link's: the tangent basis of
// its normal and the combined material of its two shapes.
#ifndef RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_FRAME_H_
#define RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_FRAME_H_

#include <array>

#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// The tangent basis of a contact normal: a unit t1 orthogonal to n, and
// t2 = n x t1. It depends on n only, so warm starts carry over.
std::array<Vec3, 2> TangentBasis(const Vec3& normal);

// Combination rules: e = max(ea, eb), mu = sqrt(mu_a mu_b).
double CombineRestitution(double restitution_a, double restitution_b);
double CombineFriction(double friction_a, double friction_b);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_FRAME_H_
