// What every stage of one step reads: the interval it advances, the
// settings and the task pool. WorldImpl::Step makes one; a time-of-impact
// sub-step makes its own for the rest of the step (Interval). Box2D v3
// passes its stages a b2StepContext for the same reason: one value instead
// of dt threaded through every signature.
#ifndef RIGID_BODY_SIM_PHYSICS_WORLD_STEP_CONTEXT_H_
#define RIGID_BODY_SIM_PHYSICS_WORLD_STEP_CONTEXT_H_

#include <cassert>

#include "physics/world/task_pool.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

struct StepContext {
  // The whole step: `settings.time_step`.
  StepContext(const WorldSettings& world_settings, TaskPool* task_pool)
      : dt(world_settings.time_step),
        step_dt(world_settings.time_step),
        settings(&world_settings),
        pool(task_pool) {
    assert(dt > 0.0);
  }

  // The same step's remaining `h` seconds (a sub-step after an impact):
  // the stages then advance h, while step_dt stays the whole step.
  StepContext Interval(double h) const {
    assert(h > 0.0 && h <= step_dt);
    StepContext sub = *this;
    sub.dt = h;
    return sub;
  }

  double dt;       // s, the interval the stages advance (the step, or a sub-step)
  double step_dt;  // s, the whole step
  const WorldSettings* settings;
  TaskPool* pool;  // settings->threads threads
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_WORLD_STEP_CONTEXT_H_
