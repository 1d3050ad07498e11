// An articulation's free motion over one step, by classical RK4 checked
// against the energy balance (docs/design.md, "Articulated bodies", "Free
// motion that keeps its energy"; articulation_free_motion.cc).
#ifndef RIGID_BODY_SIM_PHYSICS_ARTICULATION_FREE_MOTION_H_
#define RIGID_BODY_SIM_PHYSICS_ARTICULATION_FREE_MOTION_H_

#include <array>

#include <Eigen/Core>

#include "physics/articulation/articulation_dynamics.h"

namespace rigid_body_sim::physics {

// An articulation's energy at a state's kinematics.
struct Energy {
  double kinetic = 0.0;    // J
  double potential = 0.0;  // J, of gravity, zero at the world's origin
  double magnitude = 0.0;  // J, the sum of the terms' magnitudes
};

// E = sum_i (m_i v_i^2 / 2 + omega_i . I_i omega_i / 2 - m_i g . c_i) over
// the links that move (articulation_free_motion.cc).
Energy EnergyOf(const ArticulationModel& model, const ArticulationKinematics& k,
                const Vec3& gravity);

// One free step's inputs.
struct FreeMotionStep {
  const ArticulationModel& model;
  const ArticulationState& state;
  // Of `state`: its links' poses and velocities.
  const ArticulationKinematics& kinematics;
  const Vec3& gravity;                   // m/s^2
  const Eigen::VectorXd& joint_efforts;  // per dof, N m or N
  double dt;                             // s
  // u' at `state` with the damping explicit, when the caller has it: the
  // first RK4 stage then reuses it instead of computing it again.
  const Eigen::VectorXd* start_acceleration = nullptr;
};

// Where a step ends: its state and that state's kinematics (poses and
// velocities), which place the links and start the next step.
struct FreeMotionEnd {
  ArticulationState* state;
  ArticulationKinematics* kinematics;
};

// The free motion of one articulation, step after step. A step is one RK4
// step, or 2, 4, ... up to MostParts equal ones where the whole step would
// miss the energy balance E1 = E0 + W (the efforts' work W) by more than
// 1e-4 of the kinetic energy; what is left of the miss is then projected
// away by scaling u. At MostParts the step is taken whatever its miss: a
// large model's cost per step is bounded, and it is its accuracy, not its
// energy, that gives way. A step starts from the last one's split, or half of
// it when the last miss, grown as RK4's error grows, would pass. Without
// joint damping or wrenches on the links the energy is kept to rounding;
// with damping the balance is a bound (E1 <= E0 + W), and only a gain is
// projected away. With wrenches on links the balance is not checked. Its
// buffers keep their size from step to step, so that a step allocates
// nothing once they have their model's.
class FreeMotionIntegrator {
 public:
  static constexpr int kMaxParts = 64;
  // The most RK4 parts times moving links one step may spend: about 4 ms
  // on this project's machines (1 us per link and part), so that a
  // 1000-link chain steps in a few milliseconds whatever its motion needs.
  static constexpr std::size_t kLinkPartBudget = 4096;
  // The most parts a step of `model` may take: kMaxParts, halved while
  // parts times moving links exceed kLinkPartBudget (at least 1).
  static int MostParts(const ArticulationModel& model);

  void Step(const FreeMotionStep& step, const FreeMotionEnd& end);
  // Forgets the splits the last steps needed (a teleport), keeping the
  // buffers: the next step starts as the first did.
  void Restart();
  // RK4 steps the last step took.
  int parts() const { return parts_; }

 private:
  void StepInParts(const FreeMotionStep& step, int parts, ArticulationState* next);
  // One RK4 step of h from `start` into `next` (which must not be `start`);
  // the first stage reuses step.start_acceleration when `from_step_start`.
  void RungeKuttaStep(const FreeMotionStep& step, const ArticulationState& start, double h,
                      bool from_step_start, ArticulationState* next);
  // u' at `state`, into `acceleration`.
  void Accelerate(const FreeMotionStep& step, const ArticulationState& state,
                  Eigen::VectorXd* acceleration);

  int parts_ = 1;
  // The last checked step's miss over its tolerance (negative for a loss
  // where the balance is a bound), and the steps to wait before fewer parts
  // are tried again.
  double last_ratio_ = 1.0;
  int steps_before_retry_ = 0;
  ArticulationKinematics kinematics_;  // a stage's
  ArticulatedBodyScratch dynamics_;
  ArticulationState part_start_;
  ArticulationState stage_;
  std::array<Eigen::VectorXd, 4> stage_acceleration_;
  Eigen::VectorXd velocity_sum_;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_ARTICULATION_FREE_MOTION_H_
