// The exact solver behind the MotionSolver seam: Baraff's classification of
// every contact by its relative normal velocity, collision impulses with
// restitution, resting contact for all contacts at once, and the time of
// impact found instead of tunnelling (docs/design.md, stages 4 and 5). Its
// stages are WorldImpl's (step_solver.cc, step_integrator.cc,
// step_impacts.cc), which hold their state.
#include "physics/solver/motion_solver.h"
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {

class ExactSolver final : public MotionSolver {
 public:
  explicit ExactSolver(WorldImpl* world) : world_(*world) {}
  void Solve(const StepContext& step) override { world_.SolveContacts(step); }
  void Integrate(const StepContext& step) override { world_.IntegrateBodies(step); }

 private:
  WorldImpl& world_;
};

std::unique_ptr<MotionSolver> MakeMotionSolver(MotionSolverKind kind, WorldImpl* world) {
  switch (kind) {
    case MotionSolverKind::kExact:
      break;
    case MotionSolverKind::kSoftStep:
      return MakeSoftStepSolver(world);
  }
  return std::make_unique<ExactSolver>(world);
}

}  // namespace rigid_body_sim::physics
