// What every contact row shares, a body's or a link's: the class of its
// point, the tangent basis of its normal, the combined material of its two
// shapes, the friction disc its tangential impulse is projected onto, and
// the share of restitution that adds no energy.
#ifndef RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_FRAME_H_
#define RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_FRAME_H_

#include <algorithm>
#include <array>
#include <cmath>

#include "rigid_body_sim/physics/contact.h"
#include "rigid_body_sim/physics/types.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

// A point classified by its relative normal velocity v_r = n . (pa' - pb')
// (Baraff 1997, "Rigid Body Simulation II", section 8): touching (apart by
// at most contact_tolerance), it is colliding when v_r < -epsilon, resting
// when |v_r| <= epsilon and separating when v_r > epsilon, with epsilon =
// collision_velocity_threshold. A point further apart is separating: the
// time of impact, not this step's impulse, finds when it touches.
inline ContactType ClassifyContactPoint(double separation, double normal_velocity,
                                        const SolverSettings& settings) {
  const double epsilon = settings.collision_velocity_threshold;
  if (separation > settings.contact_tolerance) return ContactType::kSeparating;
  if (normal_velocity < -epsilon) return ContactType::kColliding;
  if (normal_velocity <= epsilon) return ContactType::kResting;
  return ContactType::kSeparating;
}

// The tangent basis of a contact normal: a unit t1 orthogonal to n, and
// t2 = n x t1. It depends on n only, so warm starts carry over.
std::array<Vec3, 2> TangentBasis(const Vec3& normal);

// Combination rules: e = max(ea, eb), mu = sqrt(mu_a mu_b).
double CombineRestitution(double restitution_a, double restitution_b);
double CombineFriction(double friction_a, double friction_b);

// The largest s in [0, 1] with gain(s) = b s + q s^2 <= room: how much of
// its restitution impulses a collision may apply without adding energy.
inline double RestitutionScale(double b, double q, double room) {
  if (room <= 0.0) return 0.0;
  if (b + q <= room) return 1.0;
  double scale = 0.0;
  if (q > 0.0) {
    scale = (-b + std::sqrt(b * b + 4.0 * q * room)) / (2.0 * q);
  } else if (b > 0.0) {
    scale = room / b;
  }
  return std::clamp(scale, 0.0, 1.0);
}

// Projects the tangential impulse onto the disc |t| <= limit (a circular
// friction cone, so there is no directional bias).
inline void ClampToDisc(double limit, std::array<double, 2>* tangent) {
  // sqrt of the sum of squares: hypot's care for overflow costs more than
  // the whole row update, and impulses are nowhere near 1e150.
  const double norm_squared = (*tangent)[0] * (*tangent)[0] + (*tangent)[1] * (*tangent)[1];
  if (norm_squared > limit * limit) {
    const double norm = std::sqrt(norm_squared);
    const double scale = norm > 0.0 ? limit / norm : 0.0;
    (*tangent)[0] *= scale;
    (*tangent)[1] *= scale;
  }
}

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_FRAME_H_
