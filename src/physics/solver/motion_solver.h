// The seam between the world's stages and the solver that takes the bodies
// from their velocities to their positions: the contact solve (stage 4) and
// the integration with its impacts (stage 5). The world builds the contact
// problem's input (broad and narrow phase, contact cache, the articulations'
// dynamics) and orders the stages; a MotionSolver, chosen by
// WorldSettings::motion_solver, runs these two: the exact solver
// (exact_solver.cc) or the soft step (soft_step_solver.cc). Neither changes
// collision, contact building or articulation dynamics.
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_MOTION_SOLVER_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_MOTION_SOLVER_H_

#include <memory>

#include "physics/world/step_context.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

class WorldImpl;

class MotionSolver {
 public:
  virtual ~MotionSolver() = default;
  // Stage 4: new velocities from the touching pairs and the forces, the
  // contact impulses, and the contact reports.
  virtual void Solve(const StepContext& step) = 0;
  // Stage 5: new poses from the velocities, the impacts within the step
  // found and resolved, and sleep.
  virtual void Integrate(const StepContext& step) = 0;
};

// The solver of `kind` for `world`, which outlives it.
std::unique_ptr<MotionSolver> MakeMotionSolver(MotionSolverKind kind, WorldImpl* world);
// The soft step (soft_step_solver.cc).
std::unique_ptr<MotionSolver> MakeSoftStepSolver(WorldImpl* world);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_MOTION_SOLVER_H_
