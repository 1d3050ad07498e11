// The contacts a step reports: their type by relative normal velocity, and
// their impulses.
#ifndef RIGID_BODY_SIM_PHYSICS_CONTACT_H_
#define RIGID_BODY_SIM_PHYSICS_CONTACT_H_

#include <array>
#include <cstdint>

#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// Baraff's classification by relative normal velocity v_r = n . (pa' - pb').
enum class ContactType : std::uint8_t {
  kColliding = 1,   // v_r < -epsilon: resolved by an impulse
  kResting = 2,     // |v_r| <= epsilon: resolved by contact forces
  kSeparating = 3,  // v_r > epsilon
};

// One contact point as reported to users after a step.
struct ContactReport {
  BodyId body_a;
  BodyId body_b;
  int shape_a = 0;  // index into body A's shapes
  int shape_b = 0;
  Vec3 position_world = Vec3::Zero();  // m
  Vec3 normal_world = Vec3::UnitZ();   // unit, from B towards A
  double depth = 0.0;                  // m, penetration, >= 0
  double normal_velocity = 0.0;        // m/s, v_r before resolution; < 0 approaching
  ContactType type = ContactType::kResting;
  double normal_impulse = 0.0;                 // N s, along the normal, in the step it was resolved
  Vec3 friction_impulse_world = Vec3::Zero();  // N s
  double normal_force = 0.0;                   // N, normal_impulse / time_step
};

// A body that interpenetrates another, as World::FindOverlaps reports it.
struct BodyOverlap {
  BodyId other;
  double depth = 0.0;  // m, deepest penetration of any shape pair, > 0
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_CONTACT_H_
