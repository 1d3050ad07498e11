// The scenes in Bullet 3.24 (Debian libbullet-dev), with its defaults:
// btDiscreteDynamicsWorld, btDbvtBroadphase, btSequentialImpulseConstraintSolver
// with 10 iterations, split impulse and warm starting, its own sleeping, one
// fixed step of 1/240 s per stepSimulation call (no substeps).
//
// Materials. Bullet multiplies the coefficients of the two bodies:
// mu = mu_a mu_b and e = e_a e_b. Ours are mu = sqrt(mu_a mu_b) and
// e = max(e_a, e_b). Per body, Bullet gets
//   friction    sqrt(mu_i), so sqrt(mu_a) sqrt(mu_b) = sqrt(mu_a mu_b) for every pair;
//   restitution e_i for the dynamic bodies and 1 for the ground, so a body
//               against the ground gets e_i = max(e_i, 0) when our ground has e = 0.
// Between two dynamic bodies e_a e_b = max(e_a, e_b) only when both are 0,
// so a scene may have a bouncing body only when it is the only body; the
// scenes satisfy this and the constructor checks it.
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "engine.h"

namespace rigid_body_sim::bench {
namespace {

using Clock = std::chrono::steady_clock;

double ElapsedMs(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

btVector3 ToBullet(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
Vec3 FromBullet(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }
btTransform ToBullet(const Pose& pose) {
  const Quat& q = pose.rotation;
  return btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), ToBullet(pose.translation));
}

// btDiscreteDynamicsWorld with each stage of internalSingleStepSimulation
// timed: broad phase = AABB update and pair search; narrow phase = the rest
// of collision detection (manifolds); solver = solveConstraints (islands'
// constraint solve); integrator = velocity prediction, transform
// integration and deactivation.
class TimedWorld : public btDiscreteDynamicsWorld {
 public:
  using btDiscreteDynamicsWorld::btDiscreteDynamicsWorld;

  void ResetTimes() { times_ = StageTimes(); }
  const StageTimes& times() const { return times_; }

  void updateAabbs() override {
    const Clock::time_point start = Clock::now();
    btDiscreteDynamicsWorld::updateAabbs();
    times_.broad_phase_ms += ElapsedMs(start, Clock::now());
  }
  void computeOverlappingPairs() override {
    const Clock::time_point start = Clock::now();
    btDiscreteDynamicsWorld::computeOverlappingPairs();
    times_.broad_phase_ms += ElapsedMs(start, Clock::now());
  }
  void performDiscreteCollisionDetection() override {
    const double broad_before = times_.broad_phase_ms;
    const Clock::time_point start = Clock::now();
    btDiscreteDynamicsWorld::performDiscreteCollisionDetection();
    const double total = ElapsedMs(start, Clock::now());
    times_.narrow_phase_ms += total - (times_.broad_phase_ms - broad_before);
  }
  void solveConstraints(btContactSolverInfo& solver_info) override {
    const Clock::time_point start = Clock::now();
    btDiscreteDynamicsWorld::solveConstraints(solver_info);
    times_.solver_ms += ElapsedMs(start, Clock::now());
  }

 protected:
  void predictUnconstraintMotion(btScalar time_step) override {
    const Clock::time_point start = Clock::now();
    btDiscreteDynamicsWorld::predictUnconstraintMotion(time_step);
    times_.integrator_ms += ElapsedMs(start, Clock::now());
  }
  void integrateTransforms(btScalar time_step) override {
    const Clock::time_point start = Clock::now();
    btDiscreteDynamicsWorld::integrateTransforms(time_step);
    times_.integrator_ms += ElapsedMs(start, Clock::now());
  }
  void updateActivationState(btScalar time_step) override {
    const Clock::time_point start = Clock::now();
    btDiscreteDynamicsWorld::updateActivationState(time_step);
    times_.integrator_ms += ElapsedMs(start, Clock::now());
  }

 private:
  StageTimes times_;
};

class BulletEngine : public Engine {
 public:
  explicit BulletEngine(const Scene& scene)
      : dispatcher_(&configuration_),
        world_(&dispatcher_, &broad_phase_, &solver_, &configuration_) {
    world_.setGravity(btVector3(0.0, 0.0, -9.81));
    int bouncing = 0;
    for (const BenchBody& body : scene.bodies) bouncing += body.material.restitution > 0.0;
    assert(scene.ground_material.restitution == 0.0 && bouncing <= 1 &&
           (bouncing == 0 || scene.bodies.size() == 1));
    (void)bouncing;

    const Vec3 normal = scene.world_from_ground.rotation * Vec3::UnitZ();
    if (scene.terrain.triangles.empty()) {
      ground_shape_ = std::make_unique<btStaticPlaneShape>(
          ToBullet(normal), normal.dot(scene.world_from_ground.translation));
    } else {
      // The terrain as Bullet's static triangle mesh with its AABB tree
      // (btBvhTriangleMeshShape, quantized), over the scene's own arrays.
      terrain_vertices_.reserve(3 * scene.terrain.vertices.size());
      for (const Vec3& vertex : scene.terrain.vertices) {
        for (int k = 0; k < 3; ++k) terrain_vertices_.push_back(vertex[k]);
      }
      for (const Eigen::Vector3i& triangle : scene.terrain.triangles) {
        for (int k = 0; k < 3; ++k) terrain_indices_.push_back(triangle[k]);
      }
      terrain_arrays_ = std::make_unique<btTriangleIndexVertexArray>(
          static_cast<int>(scene.terrain.triangles.size()), terrain_indices_.data(),
          static_cast<int>(3 * sizeof(int)), static_cast<int>(scene.terrain.vertices.size()),
          terrain_vertices_.data(), static_cast<int>(3 * sizeof(btScalar)));
      ground_shape_ = std::make_unique<btBvhTriangleMeshShape>(terrain_arrays_.get(), true);
    }
    btRigidBody::btRigidBodyConstructionInfo ground_info(0.0, nullptr, ground_shape_.get());
    ground_info.m_friction = std::sqrt(scene.ground_material.friction);
    ground_info.m_restitution = 1.0;
    rigid_bodies_.push_back(std::make_unique<btRigidBody>(ground_info));
    world_.addRigidBody(rigid_bodies_.back().get());

    for (const BenchBody& body : scene.bodies) {
      btCollisionShape* shape = nullptr;
      for (std::size_t i = 0; i < shape_keys_.size(); ++i) {
        if (shape_keys_[i].first == body.shape &&
            shape_keys_[i].second == (body.shape == BenchBody::Shape::kBox
                                          ? body.box_size
                                          : Vec3::Constant(body.sphere_radius))) {
          shape = shapes_[i].get();
        }
      }
      if (shape == nullptr) {
        if (body.shape == BenchBody::Shape::kBox) {
          shapes_.push_back(std::make_unique<btBoxShape>(ToBullet(0.5 * body.box_size)));
          shape_keys_.emplace_back(body.shape, body.box_size);
        } else {
          shapes_.push_back(std::make_unique<btSphereShape>(body.sphere_radius));
          shape_keys_.emplace_back(body.shape, Vec3::Constant(body.sphere_radius));
        }
        shape = shapes_.back().get();
      }
      btVector3 inertia(0.0, 0.0, 0.0);
      shape->calculateLocalInertia(body.mass, inertia);
      btRigidBody::btRigidBodyConstructionInfo info(body.mass, nullptr, shape, inertia);
      info.m_startWorldTransform = ToBullet(body.world_from_body);
      info.m_friction = std::sqrt(body.material.friction);
      info.m_restitution = body.material.restitution;
      rigid_bodies_.push_back(std::make_unique<btRigidBody>(info));
      world_.addRigidBody(rigid_bodies_.back().get());
    }
  }

  ~BulletEngine() override {
    for (auto& body : rigid_bodies_) world_.removeRigidBody(body.get());
  }

  std::string name() const override { return "bullet"; }

  void Step() override {
    world_.ResetTimes();
    world_.stepSimulation(kTimeStep, 0);
  }

  StageTimes LastStageTimes() const override {
    StageTimes times = world_.times();
    // The points of the manifolds the solver saw: those with an awake body.
    for (int m = 0; m < dispatcher_.getNumManifolds(); ++m) {
      const btPersistentManifold* manifold = dispatcher_.getManifoldByIndexInternal(m);
      if (manifold->getBody0()->isActive() || manifold->getBody1()->isActive()) {
        times.solver_points += static_cast<std::size_t>(manifold->getNumContacts());
      }
    }
    times.point_iterations = times.solver_points * static_cast<std::size_t>(solver_iterations_);
    return times;
  }

  Vec3 Position(int index) const override {
    return FromBullet(rigid_bodies_[index + 1]->getWorldTransform().getOrigin());
  }
  Vec3 LinearVelocity(int index) const override {
    return FromBullet(rigid_bodies_[index + 1]->getLinearVelocity());
  }

  // T = 1/2 m v^2 + 1/2 sum_i I_i (R^T omega)_i^2 over the dynamic bodies.
  double KineticEnergy() const override {
    double energy = 0.0;
    for (std::size_t i = 1; i < rigid_bodies_.size(); ++i) {
      const btRigidBody& body = *rigid_bodies_[i];
      const btVector3 omega_body =
          body.getWorldTransform().getBasis().transpose() * body.getAngularVelocity();
      const btVector3 inertia = body.getLocalInertia();
      energy += 0.5 / body.getInvMass() * body.getLinearVelocity().length2() +
                0.5 * (inertia * omega_body).dot(omega_body);
    }
    return energy;
  }

  double MaxPenetration() const override {
    double depth = 0.0;
    for (int m = 0; m < dispatcher_.getNumManifolds(); ++m) {
      const btPersistentManifold* manifold = dispatcher_.getManifoldByIndexInternal(m);
      for (int p = 0; p < manifold->getNumContacts(); ++p) {
        depth = std::max(depth, -static_cast<double>(manifold->getContactPoint(p).getDistance()));
      }
    }
    return depth;
  }

  // A normal row and one friction row: the default solver mode leaves out
  // SOLVER_USE_2_FRICTION_DIRECTIONS.
  int RowsPerPoint() const override { return 2; }

 private:
  btDefaultCollisionConfiguration configuration_;
  // Bullet reads manifolds through non-const accessors only.
  mutable btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broad_phase_;
  btSequentialImpulseConstraintSolver solver_;
  TimedWorld world_;
  int solver_iterations_ = world_.getSolverInfo().m_numIterations;
  // The terrain's arrays, before the shape that reads them.
  std::vector<btScalar> terrain_vertices_;
  std::vector<int> terrain_indices_;
  std::unique_ptr<btTriangleIndexVertexArray> terrain_arrays_;
  std::unique_ptr<btCollisionShape> ground_shape_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::pair<BenchBody::Shape, Vec3>> shape_keys_;
  std::vector<std::unique_ptr<btRigidBody>> rigid_bodies_;
};

}  // namespace

std::unique_ptr<Engine> MakeBulletEngine(const Scene& scene) {
  return std::make_unique<BulletEngine>(scene);
}

}  // namespace rigid_body_sim::bench
