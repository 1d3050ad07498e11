#include "bullet_common.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace rigid_body_sim::bench {

void ApplyBulletSleep(const BulletSleep& sleep) {
  if (sleep.like_ours) gDeactivationTime = static_cast<btScalar>(sleep.time_to_sleep);
}

BulletBodies::BulletBodies(const Scene& scene, const BulletSleep& sleep,
                           btDiscreteDynamicsWorld* world)
    : world_(world) {
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
    // The terrain as Bullet's static triangle mesh with its quantized AABB
    // tree (btBvhTriangleMeshShape), over copies of the scene's arrays.
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
  ground_ = std::make_unique<btRigidBody>(ground_info);
  world_->addRigidBody(ground_.get());

  for (const BenchBody& body : scene.bodies) {
    btCollisionShape* shape = Shape(body);
    btVector3 inertia(0.0, 0.0, 0.0);
    shape->calculateLocalInertia(body.mass, inertia);
    btRigidBody::btRigidBodyConstructionInfo info(body.mass, nullptr, shape, inertia);
    info.m_startWorldTransform = ToBullet(body.world_from_body);
    info.m_friction = std::sqrt(body.material.friction);
    info.m_restitution = body.material.restitution;
    if (sleep.like_ours) {
      info.m_linearSleepingThreshold = static_cast<btScalar>(sleep.linear_velocity);
      info.m_angularSleepingThreshold = static_cast<btScalar>(sleep.angular_velocity);
    }
    bodies_.push_back(std::make_unique<btRigidBody>(info));
    world_->addRigidBody(bodies_.back().get());
  }
}

BulletBodies::~BulletBodies() {
  for (auto& body : bodies_) world_->removeRigidBody(body.get());
  world_->removeRigidBody(ground_.get());
}

btCollisionShape* BulletBodies::Box(const Vec3& size) {
  BenchBody box;
  box.shape = BenchBody::Shape::kBox;
  box.box_size = size;
  return Shape(box);
}

btCollisionShape* BulletBodies::Shape(const BenchBody& body) {
  const bool is_box = body.shape == BenchBody::Shape::kBox;
  const Vec3 key = is_box ? body.box_size : Vec3::Constant(body.sphere_radius);
  for (std::size_t i = 0; i < shape_keys_.size(); ++i) {
    if (shape_keys_[i].first == body.shape && shape_keys_[i].second == key) {
      return shapes_[i].get();
    }
  }
  if (is_box) {
    shapes_.push_back(std::make_unique<btBoxShape>(ToBullet(0.5 * body.box_size)));
  } else {
    shapes_.push_back(std::make_unique<btSphereShape>(body.sphere_radius));
  }
  shape_keys_.emplace_back(body.shape, key);
  return shapes_.back().get();
}

bool BulletBodies::AllAwake() const {
  return std::all_of(bodies_.begin(), bodies_.end(),
                     [](const std::unique_ptr<btRigidBody>& body) { return body->isActive(); });
}

double BulletBodies::KineticEnergy() const {
  double energy = 0.0;
  for (const std::unique_ptr<btRigidBody>& body : bodies_) {
    const btVector3 omega_body =
        body->getWorldTransform().getBasis().transpose() * body->getAngularVelocity();
    const btVector3 inertia = body->getLocalInertia();
    energy += 0.5 / body->getInvMass() * body->getLinearVelocity().length2() +
              0.5 * (inertia * omega_body).dot(omega_body);
  }
  return energy;
}

double BulletBodies::MechanicalEnergy() const {
  double energy = KineticEnergy();
  for (const std::unique_ptr<btRigidBody>& body : bodies_) {
    energy += kGravity / body->getInvMass() * body->getCenterOfMassPosition().z();
  }
  return energy;
}

double BulletMaxPenetration(btCollisionDispatcher* dispatcher) {
  double depth = 0.0;
  for (int m = 0; m < dispatcher->getNumManifolds(); ++m) {
    const btPersistentManifold* manifold = dispatcher->getManifoldByIndexInternal(m);
    for (int p = 0; p < manifold->getNumContacts(); ++p) {
      depth = std::max(depth, -static_cast<double>(manifold->getContactPoint(p).getDistance()));
    }
  }
  return depth;
}

std::size_t BulletSolverPoints(btCollisionDispatcher* dispatcher) {
  std::size_t points = 0;
  for (int m = 0; m < dispatcher->getNumManifolds(); ++m) {
    const btPersistentManifold* manifold = dispatcher->getManifoldByIndexInternal(m);
    if (manifold->getBody0()->isActive() || manifold->getBody1()->isActive()) {
      points += static_cast<std::size_t>(manifold->getNumContacts());
    }
  }
  return points;
}

}  // namespace rigid_body_sim::bench
