// Ray casts against the world's shapes (World::CastRays).
#ifndef RIGID_BODY_SIM_PHYSICS_RAY_H_
#define RIGID_BODY_SIM_PHYSICS_RAY_H_

#include <cstddef>
#include <limits>

#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// origin + t direction for t in [0, max_distance].
struct Ray {
  Vec3 origin = Vec3::Zero();                                     // m, world
  Vec3 direction = Vec3::UnitX();                                 // unit, world
  double max_distance = std::numeric_limits<double>::infinity();  // m, >= 0
};

// The first surface a ray enters within its length. A ray that starts
// inside a solid does not hit that solid (it leaves it, it does not enter
// it); a static mesh's closed parts are hit from outside only, its open
// parts (a terrain, a sheet) from either side.
struct RayHit {
  bool hit = false;
  double distance = std::numeric_limits<double>::infinity();  // m, t of the hit
  Vec3 point = Vec3::Zero();                                  // m, world
  Vec3 normal = Vec3::Zero();  // unit, world, the surface's, against the ray
  BodyId body;                 // the body hit (World::CastRays)
  int shape = -1;              // its shape, in BodyDef::shapes order
};

// Most rays one World::CastRays takes.
constexpr std::size_t kMaxRaysPerCast = std::size_t{1} << 20;

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_RAY_H_
