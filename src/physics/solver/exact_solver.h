// The exact solver behind the MotionSolver seam: Baraff's classification of
// every contact by its relative normal velocity, collision impulses with
// restitution, resting contact for all contacts at once (stage 4,
// exact_solver.cc), and the time of impact found instead of tunnelling
// (stage 5: the drift and the search, exact_integrate.cc; the impact and
// the rest of the step, exact_impacts.cc). It holds the state only it
// uses; the world's bodies, contacts and contact solver it reaches as
// WorldImpl's friend, as the soft step does.
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_EXACT_SOLVER_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_EXACT_SOLVER_H_

#include <cstdint>
#include <vector>

#include "physics/contact/contact_cache.h"
#include "physics/dynamics/integrator.h"
#include "physics/solver/motion_solver.h"
#include "physics/world/step_context.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

class WorldImpl;

// A pair that comes into contact within a (sub)step, and when.
struct Impact {
  ShapePairContact* pair = nullptr;
  double time = 0.0;       // s from the (sub)step's start
  bool colliding = false;  // the surfaces meet faster than collision_velocity_threshold
};

class ExactSolver final : public MotionSolver {
 public:
  explicit ExactSolver(WorldImpl* world);
  void Solve(const StepContext& step) override;
  void Integrate(const StepContext& step) override;

 private:
  // Stage 4 (exact_solver.cc).
  void SolveContacts(const StepContext& step);
  // The contact solve of `pairs` over step.dt for the world's moving bodies.
  void SolveTouching(const StepContext& step, const std::vector<ShapePairContact*>& pairs);
  void HoldPushedBodies();
  // Stage 5 (exact_integrate.cc, exact_impacts.cc).
  void IntegrateBodies(const StepContext& step);
  void CapSpin(const StepContext& step);
  void DriftBodies(const StepContext& step);
  void BoundBodyMotion(const StepContext& step);
  std::vector<Impact> FindImpacts(const StepContext& step,
                                  const std::vector<ShapePairContact*>& pairs);
  // Time of impact within dt, or +infinity; with the speed the surfaces
  // meet at, m/s.
  double PairImpactTime(const StepContext& step, ShapePairContact* pair, double* approach_speed);
  void ResolveImpacts(const StepContext& step, const std::vector<Impact>& impacts,
                      const std::vector<ShapePairContact*>& touching, int round);
  void BackUpBody(std::uint32_t index, double time);
  void SubStep(const std::vector<std::uint32_t>& island, const StepContext& step, int round);
  int PathSamples(std::uint32_t body_a, std::uint32_t body_b) const;
  double PairThickness(const ShapePairContact& pair) const;
  double PairStartGap(const ShapePairContact& pair) const;

  WorldImpl& world_;
  std::vector<Vec3> push_normals_;        // HoldPushedBodies' scratch, per body slot
  std::vector<std::uint8_t> push_state_;  // 0 not pushed, 1 along one normal, 2 several
  std::vector<BodyPath> paths_;           // stage 5's, per body slot (IntegrateBodies)
  // FindImpacts' per pair: the time of impact (s, +infinity for none) and
  // the speed the surfaces meet at (m/s).
  struct ImpactSearch {
    double time = 0.0;
    double approach_speed = 0.0;
  };
  std::vector<ImpactSearch> impact_searches_;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_EXACT_SOLVER_H_
