// What the two Bullet engines of the benchmark share (bullet_engine.cc,
// bullet_multibody_engine.cc): conversions, a world with each stage timed,
// and the free bodies and the ground of a scene, with the material and
// sleep rules of bullet_engine.cc.
#ifndef RIGID_BODY_SIM_BENCH_BULLET_COMMON_H_
#define RIGID_BODY_SIM_BENCH_BULLET_COMMON_H_

#include <btBulletDynamicsCommon.h>

#include <chrono>
#include <memory>
#include <utility>
#include <vector>

#include "engine.h"
#include "scene.h"

namespace rigid_body_sim::bench {

using BulletClock = std::chrono::steady_clock;

inline double ElapsedMs(BulletClock::time_point from, BulletClock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

inline btVector3 ToBullet(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
inline Vec3 FromBullet(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }
inline btTransform ToBullet(const Pose& pose) {
  const Quat& q = pose.rotation;
  return btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), ToBullet(pose.translation));
}

// A Bullet world (btDiscreteDynamicsWorld or a subclass) with each stage of
// internalSingleStepSimulation timed: broad phase = AABB update and pair
// search; narrow phase = the rest of collision detection (manifolds);
// solver = solveConstraints (islands' constraint solve; for btMultiBody
// also its forward dynamics, which Bullet runs there); integrator =
// velocity prediction, transform integration and deactivation.
template <class BaseWorld>
class TimedWorld : public BaseWorld {
 public:
  using BaseWorld::BaseWorld;

  void ResetTimes() { times_ = StageTimes(); }
  const StageTimes& times() const { return times_; }

  void updateAabbs() override {
    Timed(&times_.broad_phase_ms, [&] { BaseWorld::updateAabbs(); });
  }
  void computeOverlappingPairs() override {
    Timed(&times_.broad_phase_ms, [&] { BaseWorld::computeOverlappingPairs(); });
  }
  void performDiscreteCollisionDetection() override {
    const double broad_before = times_.broad_phase_ms;
    double total = 0.0;
    Timed(&total, [&] { BaseWorld::performDiscreteCollisionDetection(); });
    times_.narrow_phase_ms += total - (times_.broad_phase_ms - broad_before);
  }
  void solveConstraints(btContactSolverInfo& solver_info) override {
    Timed(&times_.solver_ms, [&] { BaseWorld::solveConstraints(solver_info); });
  }

 protected:
  void predictUnconstraintMotion(btScalar time_step) override {
    Timed(&times_.integrator_ms, [&] { BaseWorld::predictUnconstraintMotion(time_step); });
  }
  void integrateTransforms(btScalar time_step) override {
    Timed(&times_.integrator_ms, [&] { BaseWorld::integrateTransforms(time_step); });
  }
  void updateActivationState(btScalar time_step) override {
    Timed(&times_.integrator_ms, [&] { BaseWorld::updateActivationState(time_step); });
  }

 private:
  template <class Function>
  static void Timed(double* sum_ms, Function function) {
    const BulletClock::time_point start = BulletClock::now();
    function();
    *sum_ms += ElapsedMs(start, BulletClock::now());
  }

  StageTimes times_;
};

// Applies `sleep` to Bullet's global deactivation time; each benchmark run
// is a process of its own, so the global reaches that run only.
void ApplyBulletSleep(const BulletSleep& sleep);

// The ground and the free bodies of a scene in a Bullet world, body i of
// the scene at bodies()[i]; removes them from the world when destroyed.
class BulletBodies {
 public:
  BulletBodies(const Scene& scene, const BulletSleep& sleep, btDiscreteDynamicsWorld* world);
  ~BulletBodies();
  BulletBodies(const BulletBodies&) = delete;
  BulletBodies& operator=(const BulletBodies&) = delete;

  const std::vector<std::unique_ptr<btRigidBody>>& bodies() const { return bodies_; }
  // A box shape of full edge lengths `size`, shared by every caller.
  btCollisionShape* Box(const Vec3& size);
  bool AllAwake() const;
  // T = 1/2 m v^2 + 1/2 sum_i I_i (R^T omega)_i^2 over the free bodies.
  double KineticEnergy() const;
  // That plus m g z of each free body's centre of mass (J).
  double MechanicalEnergy() const;

 private:
  btCollisionShape* Shape(const BenchBody& body);

  btDiscreteDynamicsWorld* world_;
  // The terrain's arrays, before the shape that reads them.
  std::vector<btScalar> terrain_vertices_;
  std::vector<int> terrain_indices_;
  std::unique_ptr<btTriangleIndexVertexArray> terrain_arrays_;
  std::unique_ptr<btCollisionShape> ground_shape_;
  std::unique_ptr<btRigidBody> ground_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::pair<BenchBody::Shape, Vec3>> shape_keys_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
};

// m, the deepest penetration among the manifolds' points.
double BulletMaxPenetration(btCollisionDispatcher* dispatcher);
// The points of the manifolds the solver saw: those with an awake body.
std::size_t BulletSolverPoints(btCollisionDispatcher* dispatcher);

}  // namespace rigid_body_sim::bench

#endif  // RIGID_BODY_SIM_BENCH_BULLET_COMMON_H_
