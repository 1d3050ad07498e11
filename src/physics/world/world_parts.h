// The parts of the world that its systems (CollisionSystem, SleepSystem)
// read and write. The world owns them and outlives its systems, which keep
// references to them.
#ifndef RIGID_BODY_SIM_PHYSICS_WORLD_WORLD_PARTS_H_
#define RIGID_BODY_SIM_PHYSICS_WORLD_WORLD_PARTS_H_

#include <vector>

#include "physics/articulation/articulation_system.h"
#include "physics/contact/contact_cache.h"
#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

struct WorldParts {
  std::vector<Body>* bodies = nullptr;  // the world's slots
  ContactCache* contact_cache = nullptr;
  const WorldSettings* settings = nullptr;
  const ArticulationSystem* articulations = nullptr;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_WORLD_WORLD_PARTS_H_
