// Stages 1 and 2 of World::Step as one system: the broad phase's swept
// boxes and candidate pairs (step_broad_phase.cc), and the narrow phase's
// manifold for every shape pair that may touch, written into the contact
// cache (step_narrow_phase.cc). It owns the broad phase, the half-space
// list and the stages' scratch; the world owns the bodies, the contact
// cache and the settings, and tells it when a body comes, goes or leaves
// the broad phase.
#ifndef RIGID_BODY_SIM_PHYSICS_COLLISION_COLLISION_SYSTEM_H_
#define RIGID_BODY_SIM_PHYSICS_COLLISION_COLLISION_SYSTEM_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "physics/articulation/articulation_system.h"
#include "physics/collision/broad_phase.h"
#include "physics/contact/contact_cache.h"
#include "physics/world/step_context.h"
#include "physics/world/world_parts.h"
#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

// A shape pair the narrow phase tests this step: its cache entry, which
// holds the bodies, shapes and contact distance, and the summed travel of
// the two bodies (Body::travel). Jobs write only their own entry, so any
// thread may run any of them.
struct NarrowJob {
  ShapePairContact* entry = nullptr;
  double travel = 0.0;  // m
  bool reused = false;  // the manifold was carried, not clipped (out)
};

// A broad-phase pair as the narrow phase's walk first sees it, on any
// thread (CollisionSystem::VisitPair), and what the walk in the pairs'
// order then does with it (ListPair). Only a pair of two single-shape
// bodies, neither a static mesh, whose shape pair has a cache entry is
// handled on the pool; the rest are listed by CollideBodies in the ordered
// walk.
struct PairVisit {
  enum class Kind : std::uint8_t { kSkipped, kInWalk, kSeen, kNew };
  Kind kind = Kind::kSkipped;
  bool first_visit = false;  // kSeen: the entry's first visit of the step
  bool culled = false;       // kSeen: its gap cannot have closed
  std::uint32_t body_a = 0;  // kSeen, kNew: the moving body first
  std::uint32_t body_b = 0;
  ShapePairContact* entry = nullptr;  // kSeen's
  double contact_distance = 0.0;      // m, kSeen's and kNew's
  double travel = 0.0;                // m, Body::travel of both
};

class CollisionSystem {
 public:
  // Reads the bodies, the settings and the articulations' collision
  // groups; writes the contact cache.
  explicit CollisionSystem(const WorldParts& world);

  // Stage 1: every body's swept, fattened box to the broad phase.
  void UpdateBroadPhase(const StepContext& step);
  // Stage 2: the cache entry of every shape pair of the candidate body
  // pairs seen, and its manifold carried or clipped afresh. Counts a step.
  void UpdateNarrowPhase(const StepContext& step);
  // The pair's manifold clipped afresh at the current poses (the exact
  // solver's impact sub-steps).
  void RecollidePair(const StepContext& step, ShapePairContact* pair);

  // A new body in slot `index`: a half-space is tested against every body
  // near it, outside the broad phase.
  void AddBody(std::uint32_t index);
  // The body in slot `index` leaves the broad phase (it was disabled, or a
  // static body was moved); the next stage 1 adds it again if it belongs.
  void RemoveProxy(std::uint32_t index);
  // The body in slot `index` is destroyed: out of the broad phase and of
  // the half-spaces.
  void ForgetBody(std::uint32_t index);

  // Steps counted by UpdateNarrowPhase, the contact cache's clock.
  std::uint64_t step_count() const { return step_count_; }
  // Manifolds the last UpdateNarrowPhase carried instead of clipping.
  std::size_t reused_manifolds() const { return reused_manifolds_; }

 private:
  // Lists the shape pairs of two bodies that need a test (narrow_jobs_);
  // a static mesh's are tested at once.
  void CollideBodies(std::uint32_t body_a, std::uint32_t body_b, const StepContext& step);
  // CollideBodies in two halves for a pair of single shapes (PairVisit).
  void VisitPair(ProxyPair pair, const StepContext& step, PairVisit* visit);
  void ListPair(ProxyPair pair, const PairVisit& visit, const StepContext& step);
  void VisitPlane(std::uint32_t plane, const StepContext& step);
  // Tests one listed shape pair: carries its manifold or clips a new one.
  void CollideShapePair(NarrowJob* job) const;
  double ContactDistance(const Body& a, const Body& b, const StepContext& step) const;
  double ContactReach(const Body& a, const Body& b, const StepContext& step) const;
  double ContactMargin(const Body& a, const Body& b) const;
  bool ReuseManifold(const Pose& b_from_a, double reach_a, const Pose& world_from_shape_a,
                     const Pose& world_from_shape_b, ShapePairContact* entry) const;
  void AnchorManifold(const Pose& b_from_a, const Pose& world_from_shape_a,
                      const Pose& world_from_shape_b, ShapePairContact* entry) const;

  std::vector<Body>& bodies_;
  ContactCache& contact_cache_;
  const WorldSettings& settings_;
  const ArticulationSystem& articulations_;
  std::uint64_t step_count_ = 0;
  std::size_t reused_manifolds_ = 0;
  SortAndSweepBroadPhase broad_phase_;
  std::vector<std::uint32_t> proxy_bodies_;       // stage 1's: the bodies whose box is made
  std::vector<Aabb> proxy_boxes_;                 // stage 1's, per proxy_bodies_ entry
  std::vector<std::uint32_t> half_space_bodies_;  // static bodies whose one shape is a HalfSpace
  std::vector<PairVisit> pair_visits_;    // stage 2's, per broad-phase pair, then per plane pair
  std::vector<std::uint8_t> near_plane_;  // VisitPlane's, per body slot
  std::vector<ProxyPair> plane_pairs_;    // VisitPlane's: (body, plane)
  std::vector<NarrowJob> narrow_jobs_;    // stage 2's, in the order the pairs were visited
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_COLLISION_COLLISION_SYSTEM_H_
