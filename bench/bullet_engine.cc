// The scenes of free bodies in Bullet 3.24 (Debian libbullet-dev), with its
// defaults: btDiscreteDynamicsWorld, btDbvtBroadphase,
// btSequentialImpulseConstraintSolver with 10 iterations, split impulse and
// warm starting, its own sleeping, one fixed step of 1/240 s per
// stepSimulation call (no substeps).
//
// Materials. Bullet multiplies the coefficients of the two bodies:
// mu = mu_a mu_b and e = e_a e_b. Ours are mu = sqrt(mu_a mu_b) and
// e = max(e_a, e_b). Per body, Bullet gets
//   friction    sqrt(mu_i), so sqrt(mu_a) sqrt(mu_b) = sqrt(mu_a mu_b) for every pair;
//   restitution e_i for the dynamic bodies and 1 for the ground, so a body
//               against the ground gets e_i = max(e_i, 0) when our ground has e = 0.
// Between two dynamic bodies e_a e_b = max(e_a, e_b) only when both are 0,
// so a scene may have a bouncing body only when it is the only body; the
// scenes satisfy this and BulletBodies checks it.
//
// Sleep. Bullet's defaults: a body below 0.8 m/s and 1 rad/s for 2 s
// (gDeactivationTime) wants to sleep, and an island sleeps when all its
// bodies want to. BulletSleep::like_ours puts in our thresholds and time
// (physics::SleepSettings: 0.05 m/s, 0.1 rad/s, 0.5 s by default), so that
// both engines stop simulating a quiet island after the same rule; ours
// also keeps a body awake while it speeds up (speeding_up_time), which
// Bullet has no counterpart of.
#include <btBulletDynamicsCommon.h>

#include <memory>
#include <string>

#include "bullet_common.h"
#include "engine.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::bench {
namespace {

class BulletEngine : public Engine {
 public:
  BulletEngine(const Scene& scene, const BulletSleep& sleep)
      : name_(sleep.like_ours ? "bullet_oursleep" : "bullet"),
        time_step_(scene.time_step),
        dispatcher_(&configuration_),
        world_(&dispatcher_, &broad_phase_, &solver_, &configuration_) {
    ApplyBulletSleep(sleep);
    world_.setGravity(btVector3(0.0, 0.0, -9.81));
    bodies_ = std::make_unique<BulletBodies>(scene, sleep, &world_);
  }

  std::string name() const override { return name_; }

  void Step() override {
    world_.ResetTimes();
    world_.stepSimulation(static_cast<btScalar>(time_step_), 0);
  }

  StageTimes LastStageTimes() const override {
    StageTimes times = world_.times();
    times.solver_points = BulletSolverPoints(&dispatcher_);
    times.point_iterations = times.solver_points * static_cast<std::size_t>(solver_iterations_);
    return times;
  }

  Vec3 Position(int index) const override {
    return FromBullet(bodies_->bodies()[index]->getWorldTransform().getOrigin());
  }
  Vec3 LinearVelocity(int index) const override {
    return FromBullet(bodies_->bodies()[index]->getLinearVelocity());
  }
  double KineticEnergy() const override { return bodies_->KineticEnergy(); }
  double MechanicalEnergy() const override { return bodies_->MechanicalEnergy(); }
  double MaxPenetration() const override { return BulletMaxPenetration(&dispatcher_); }

  // A normal row and one friction row: the default solver mode leaves out
  // SOLVER_USE_2_FRICTION_DIRECTIONS.
  int RowsPerPoint() const override { return 2; }
  bool AllMovingBodiesAwake() const override { return bodies_->AllAwake(); }

  // No articulations in this world (MakeBulletMultiBodyEngine has them).
  double JointAnchorSeparation() const override { return 0.0; }
  double JointPosition(int) const override { return 0.0; }
  void SetMotorVelocity(int, double) override {}

 private:
  std::string name_;
  double time_step_;  // s
  btDefaultCollisionConfiguration configuration_;
  // Bullet reads manifolds through non-const accessors only.
  mutable btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broad_phase_;
  btSequentialImpulseConstraintSolver solver_;
  TimedWorld<btDiscreteDynamicsWorld> world_;
  int solver_iterations_ = world_.getSolverInfo().m_numIterations;
  std::unique_ptr<BulletBodies> bodies_;  // declared after world_: removed from it first
};

}  // namespace

std::unique_ptr<Engine> MakeBulletEngine(const Scene& scene, const BulletSleep& sleep) {
  return std::make_unique<BulletEngine>(scene, sleep);
}

std::string EngineName(EngineKind kind) {
  switch (kind) {
    case EngineKind::kOurs:
    case EngineKind::kOursTwoThreads:
    case EngineKind::kOursSoft:
    case EngineKind::kOursSoftTwoThreads:
      return "ours";
    case EngineKind::kBullet:
      return "bullet";
    case EngineKind::kBulletOurSleep:
      return "bullet_oursleep";
    case EngineKind::kMujocoRk4:
      return "mujoco_rk4";
    case EngineKind::kMujocoEuler:
      return "mujoco_euler";
  }
  return "";
}

int EngineThreads(EngineKind kind) {
  return kind == EngineKind::kOursTwoThreads || kind == EngineKind::kOursSoftTwoThreads ? 2 : 1;
}

std::string EngineSolver(EngineKind kind) {
  switch (kind) {
    case EngineKind::kOurs:
    case EngineKind::kOursTwoThreads:
      return "exact";
    case EngineKind::kOursSoft:
    case EngineKind::kOursSoftTwoThreads:
      return "soft_step";
    case EngineKind::kBullet:
    case EngineKind::kBulletOurSleep:
    case EngineKind::kMujocoRk4:
    case EngineKind::kMujocoEuler:
      break;
  }
  return "";
}

std::unique_ptr<Engine> MakeEngine(EngineKind kind, const Scene& scene,
                                   const OurSettingsOverrides& overrides) {
  if (!EngineSolver(kind).empty()) {
    OurSettingsOverrides ours = overrides;
    ours.threads = EngineThreads(kind);
    ours.motion_solver = EngineSolver(kind) == "soft_step" ? physics::MotionSolverKind::kSoftStep
                                                           : physics::MotionSolverKind::kExact;
    return MakeOurEngine(scene, ours);
  }
  if (kind == EngineKind::kMujocoRk4 || kind == EngineKind::kMujocoEuler) {
    return MakeMujocoEngine(scene, kind == EngineKind::kMujocoRk4);
  }
  BulletSleep sleep;
  if (kind == EngineKind::kBulletOurSleep) {
    const physics::SleepSettings ours;
    sleep.like_ours = true;
    sleep.linear_velocity = ours.linear_velocity;
    sleep.angular_velocity = ours.angular_velocity;
    sleep.time_to_sleep = overrides.time_to_sleep.value_or(ours.time_to_sleep);
  }
  return scene.articulations.empty() ? MakeBulletEngine(scene, sleep)
                                     : MakeBulletMultiBodyEngine(scene, sleep);
}

}  // namespace rigid_body_sim::bench
