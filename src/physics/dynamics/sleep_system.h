// Sleeping as one system, the end of stage 5 for both solvers
// (step_sleep.cc): islands of moving bodies joined by touching pairs, each
// body's quiet time (slow and not speeding up, or gone nowhere within its
// sleep window), and the islands quiet for time_to_sleep put to sleep. It
// owns the sleep windows and the islands' scratch; the world owns the
// bodies and wakes them, and restarts a body's window when it wakes, is
// created or is moved.
#ifndef RIGID_BODY_SIM_PHYSICS_DYNAMICS_SLEEP_SYSTEM_H_
#define RIGID_BODY_SIM_PHYSICS_DYNAMICS_SLEEP_SYSTEM_H_

#include <array>
#include <cstdint>
#include <vector>

#include "physics/articulation/articulation_system.h"
#include "physics/contact/contact_cache.h"
#include "physics/dynamics/sleep_window.h"
#include "physics/world/step_context.h"
#include "physics/world/union_find.h"
#include "physics/world/world_parts.h"
#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

class SleepSystem {
 public:
  // Reads the touching pairs, the settings and the articulations' link
  // pairs (which keep their islands awake); writes the bodies.
  explicit SleepSystem(const WorldParts& world);

  // Puts to sleep each island of `moving` bodies (the step's, in slot
  // order) that has been quiet for time_to_sleep; does nothing while
  // sleeping is disabled.
  void Update(const StepContext& step, const std::vector<std::uint32_t>& moving);
  // Starts the body's sleep window again (it woke, was created or moved).
  void RestartWindow(std::uint32_t body);

 private:
  bool UpdateSpeedingUp(const StepContext& step, Body* body) const;
  double QuietTime(const StepContext& step, const SleepWindowLimits& limits, bool island_has_link,
                   std::uint32_t i);

  std::vector<Body>& bodies_;
  const ContactCache& contact_cache_;
  const WorldSettings& settings_;
  const ArticulationSystem& articulations_;
  std::vector<SleepWindow> windows_;  // per body slot
  // Update's per-step buffers, kept so that a step does not allocate.
  UnionFind islands_;
  std::vector<char> island_has_link_;
  std::vector<double> island_sleep_time_;
  std::vector<std::array<std::uint32_t, 2>> edges_;  // per touching pair: bodies to join
  std::vector<std::uint32_t> root_;                  // per moving body: its island
  std::vector<double> quiet_time_;                   // s, per moving body
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_DYNAMICS_SLEEP_SYSTEM_H_
