// The seeds of supports that are new this step: the upright supports from
// the highest body down, which both solvers' seeds walk, and the soft step's
// spread of each body's load, balanced in moment as well as in force
// (docs/design.md, "The soft step").
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_SUPPORT_BALANCE_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_SUPPORT_BALANCE_H_

#include <cstdint>
#include <vector>

#include "physics/contact/contact_cache.h"
#include "physics/solver/contact_solver.h"
#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/types.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

struct SupportBalanceInput {
  const std::vector<Body>* bodies = nullptr;
  Vec3 gravity = Vec3::Zero();     // m/s^2
  double dt = 0.0;                 // s
  double contact_tolerance = 0.0;  // m: a point this close touches
};

// The input for the world's bodies over an interval of dt seconds.
SupportBalanceInput SupportInputFor(const std::vector<Body>& bodies, const WorldSettings& settings,
                                    double dt);

// A support seen from the body it holds up: manifold `manifold`, whose
// normal is within 60 degrees of up, n.up taken upward.
struct UprightSupport {
  std::uint32_t manifold;
  std::uint32_t upper;
  std::uint32_t lower;
  bool is_new;  // no point last step, and every point within contact_tolerance
  double up_along_normal;
};

// Whether a body takes a share of the loads resting on it: a static,
// sleeping or disabled body passes nothing on, as the solve never moves it.
inline bool CarriesLoad(const Body& body) {
  return !body.is_static && body.awake && !body.disabled;
}

// The upright supports, the highest upper body first (ties by index), so
// that a body's load from above is complete before it is passed on; none
// when no support is new.
std::vector<UprightSupport> UprightSupportsHighestFirst(
    const SupportBalanceInput& input, const std::vector<SolverManifold>& manifolds);

// Spreads each body's seeded load over the points of its supports so that
// they carry its weight and the loads it bears from above with no net
// moment about the vertical, as equal springs under a rigid body would: the
// least sum lambda_i^2 with sum lambda_i = L and sum lambda_i d_i = L e (N
// points at horizontal offsets d_i from their centroid, the load's line of
// action at offset e), whose Lagrange conditions make lambda_i affine in d_i:
//   lambda_i = L / N + d_i . C^+ (L e),  C = sum d_i d_i^T.
// A point that would pull (lambda_i < 0) is dropped and the rest solved
// again (support_balance.cc). Only a body whose upright supports are all
// new is spread (the others keep their cached loads); bodies are visited
// from the highest down, so each body's loads from above are known when it
// is spread. `supports` is UprightSupportsHighestFirst's list for these
// manifolds. Writes the points' normal_impulse (N s per step).
void BalanceNewSupports(const SupportBalanceInput& input,
                        const std::vector<UprightSupport>& supports,
                        std::vector<SolverManifold>* manifolds);

// A support that is new this step (a pair that had no point last step, and
// touches at every point now) starts from the load it would carry at rest:
// its points' normal impulses in *manifolds are set to it. Returns the
// upright supports it walked (none when no support is new), for the soft
// step's spread (BalanceNewSupports).
std::vector<UprightSupport> SeedNewSupportLoads(const SupportBalanceInput& input,
                                                std::vector<SolverManifold>* manifolds);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_SUPPORT_BALANCE_H_
