// The interface through which the benchmark drives each physics engine.
#ifndef RIGID_BODY_SIM_BENCH_ENGINE_H_
#define RIGID_BODY_SIM_BENCH_ENGINE_H_

#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "rigid_body_sim/physics/world_settings.h"
#include "scene.h"

namespace rigid_body_sim::bench {

// Wall time of one step split by stage. Engines whose stages differ map
// theirs onto these (bullet_engine.cc says how).
struct StageTimes {
  double broad_phase_ms = 0.0;
  double narrow_phase_ms = 0.0;  // ours: narrow phase plus contact cache
  double solver_ms = 0.0;
  double integrator_ms = 0.0;     // ours and Bullet's: integration and sleeping
  std::size_t solver_points = 0;  // contact points the solver saw
  // Point updates of the solver's velocity iterations in this step; ours
  // sweeps each island to its own convergence, so it may update fewer than
  // points x iterations.
  std::size_t point_iterations = 0;
};

class Engine {
 public:
  virtual ~Engine() = default;
  virtual std::string name() const = 0;
  // Advances by one step of the scene's time_step.
  virtual void Step() = 0;
  // Stage times of the last Step.
  virtual StageTimes LastStageTimes() const = 0;
  // Position (m, world) and linear velocity (m/s) of scene body `index`.
  virtual Vec3 Position(int index) const = 0;
  virtual Vec3 LinearVelocity(int index) const = 0;
  // J, summed over the dynamic bodies.
  virtual double KineticEnergy() const = 0;
  // J: kinetic energy plus m g z of the centre of mass, summed over every
  // body that can move (free bodies and every link but a fixed base); what
  // an articulated row's energy drift is measured on.
  virtual double MechanicalEnergy() const = 0;
  // m, the deepest penetration among the current contact points.
  virtual double MaxPenetration() const = 0;
  // Contact rows one contact point adds to a velocity iteration: with the
  // points and the iterations of StageTimes, the denominator of the cost per
  // row.
  virtual int RowsPerPoint() const = 0;
  // Whether every body that can move (every free body, every link but a
  // fixed base) is awake: the steps in which neither engine is spared work
  // by sleeping.
  virtual bool AllMovingBodiesAwake() const = 0;

  // Articulated scenes (Scene::articulations; joints numbered over all of
  // them in order). m: the largest distance between where a joint's anchor
  // is on its parent link and where it is on its child link.
  virtual double JointAnchorSeparation() const = 0;
  virtual double JointPosition(int joint) const = 0;  // rad
  // The target of the joint's velocity motor (rad/s), whose torque is capped
  // at the joint's effort limit.
  virtual void SetMotorVelocity(int joint, double velocity) = 0;
};

// Settings of our engine that a benchmark run may set to other values than
// the defaults, to measure what they cost and what they buy; unset keeps
// the default (physics::WorldSettings).
struct OurSettingsOverrides {
  std::optional<int> velocity_iterations;    // PGS sweeps per step, at most, >= 1
  std::optional<double> time_to_sleep;       // s an island must stay slow before it sleeps, > 0
  std::optional<double> velocity_tolerance;  // m/s, the sweeps' early stop, >= 0
  std::optional<bool> interleave_independent_runs;  // the sweeps pair independent runs of rows
  std::optional<bool>
      batch_independent_runs;           // the sweeps update runs four at a time in SIMD lanes
  std::optional<bool> soft_simd_lanes;  // the soft step updates four contacts at a time
  std::optional<int> threads;           // WorldSettings::threads, [0, 256]
  std::optional<physics::MotionSolverKind> motion_solver;  // WorldSettings::motion_solver
};

// The engines under test: ours on one thread; Bullet with its defaults;
// Bullet with the sleep thresholds of ours (bullet_engine.cc); ours on two
// threads; ours with the soft step (MotionSolverKind::kSoftStep) on one and
// on two threads; in the articulated scenes also MuJoCo with its RK4 and
// with its Euler integrator (mujoco_engine.cc). Bullet's multi-threaded
// world is left out: Debian's build has no thread-safe Bullet
// (performance.md).
enum class EngineKind {
  kOurs,
  kBullet,
  kBulletOurSleep,
  kOursTwoThreads,
  kMujocoRk4,
  kMujocoEuler,
  kOursSoft,
  kOursSoftTwoThreads
};
// "ours", "bullet", "bullet_oursleep", "mujoco_rk4" or "mujoco_euler"; all
// four of ours are "ours", told apart by EngineThreads and EngineSolver, so
// that the CSV's engine column keeps the values older tooling knows.
std::string EngineName(EngineKind kind);
int EngineThreads(EngineKind kind);
// Ours: its motion solver, "exact" or "soft_step"; "" for the other engines.
std::string EngineSolver(EngineKind kind);

// Bullet's sleeping: its defaults, or the thresholds of ours.
struct BulletSleep {
  bool like_ours = false;
  double linear_velocity = 0.0;   // m/s
  double angular_velocity = 0.0;  // rad/s
  double time_to_sleep = 0.0;     // s
};

std::unique_ptr<Engine> MakeOurEngine(const Scene& scene,
                                      const OurSettingsOverrides& overrides = {});
// btDiscreteDynamicsWorld for scenes of free bodies only.
std::unique_ptr<Engine> MakeBulletEngine(const Scene& scene, const BulletSleep& sleep);
// btMultiBodyDynamicsWorld (Featherstone's btMultiBody) for articulated scenes.
std::unique_ptr<Engine> MakeBulletMultiBodyEngine(const Scene& scene, const BulletSleep& sleep);
// MuJoCo for articulated scenes, integrating with RK4 or with Euler.
std::unique_ptr<Engine> MakeMujocoEngine(const Scene& scene, bool rk4);
// The engine of `kind`; Bullet's sleep thresholds of ours follow `overrides`.
std::unique_ptr<Engine> MakeEngine(EngineKind kind, const Scene& scene,
                                   const OurSettingsOverrides& overrides);

}  // namespace rigid_body_sim::bench

#endif  // RIGID_BODY_SIM_BENCH_ENGINE_H_
