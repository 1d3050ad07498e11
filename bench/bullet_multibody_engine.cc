// The articulated scenes in Bullet 3.24's reduced-coordinate multibodies:
// btMultiBodyDynamicsWorld with btMultiBodyConstraintSolver (10 iterations),
// each articulation a btMultiBody (Featherstone's articulated-body
// algorithm, semi-implicit Euler) with a fixed base, revolute links set up
// with setupRevolute, a btMultiBodyLinkCollider per link with a box, and a
// btMultiBodyJointMotor per driven joint (its impulse capped at the joint's
// effort limit times dt). The free bodies, ground, materials and sleep rule
// are those of bullet_engine.cc (BulletBodies).
//
// Matched to ours: no velocity damping on the multibody (Bullet's default
// is 0.04), a coordinate speed limit far above anything the scenes reach
// (Bullet's default clamps at 100 rad/s), and no self-collision. With
// BulletSleep::like_ours the multibodies never sleep, as ours never do.
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "bullet_common.h"
#include "engine.h"

namespace rigid_body_sim::bench {
namespace {

constexpr double kMaxCoordinateSpeed = 1e4;  // rad/s

// A joint of the scene, numbered over all its articulations: Bullet's link
// `link` of `body`, whose parent is link `parent` (-1: the base).
struct BulletJoint {
  btMultiBody* body = nullptr;
  int link = 0;
  int parent = -1;
  btVector3 anchor_from_parent_com;  // parent's centre-of-mass frame
  btVector3 anchor_from_child_com;   // child's centre-of-mass frame
  btMultiBodyJointMotor* motor = nullptr;
};

class BulletMultiBodyEngine : public Engine {
 public:
  BulletMultiBodyEngine(const Scene& scene, const BulletSleep& sleep)
      : name_(sleep.like_ours ? "bullet_oursleep" : "bullet"),
        time_step_(scene.time_step),
        dispatcher_(&configuration_),
        world_(&dispatcher_, &broad_phase_, &solver_, &configuration_) {
    ApplyBulletSleep(sleep);
    world_.setGravity(btVector3(0.0, 0.0, -9.81));
    bodies_ = std::make_unique<BulletBodies>(scene, sleep, &world_);
    for (const BenchArticulation& articulation : scene.articulations) {
      AddArticulation(articulation, sleep);
    }
  }

  ~BulletMultiBodyEngine() override {
    for (auto& motor : motors_) world_.removeMultiBodyConstraint(motor.get());
    for (auto& collider : colliders_) world_.removeCollisionObject(collider.get());
    for (auto& body : multi_bodies_) world_.removeMultiBody(body.get());
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
  double MechanicalEnergy() const override;
  double MaxPenetration() const override { return BulletMaxPenetration(&dispatcher_); }
  int RowsPerPoint() const override { return 2; }

  bool AllMovingBodiesAwake() const override {
    return bodies_->AllAwake() &&
           std::all_of(multi_bodies_.begin(), multi_bodies_.end(),
                       [](const std::unique_ptr<btMultiBody>& body) { return body->isAwake(); });
  }

  double JointAnchorSeparation() const override;

  double JointPosition(int joint) const override {
    return joints_[joint].body->getJointPos(joints_[joint].link);
  }

  void SetMotorVelocity(int joint, double velocity) override {
    if (joints_[joint].motor != nullptr) {
      joints_[joint].motor->setVelocityTarget(static_cast<btScalar>(velocity));
    }
  }

 private:
  void AddArticulation(const BenchArticulation& articulation, const BulletSleep& sleep);
  void AddColliders(const BenchArticulation& articulation, btMultiBody* body);

  std::string name_;
  double time_step_;  // s
  btDefaultCollisionConfiguration configuration_;
  mutable btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broad_phase_;
  btMultiBodyConstraintSolver solver_;
  TimedWorld<btMultiBodyDynamicsWorld> world_;
  int solver_iterations_ = world_.getSolverInfo().m_numIterations;
  std::unique_ptr<BulletBodies> bodies_;  // declared after world_: removed from it first
  std::vector<std::unique_ptr<btMultiBody>> multi_bodies_;
  btSphereShape island_marker_{0.01f};  // motored links without a box (AddColliders)
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders_;
  std::vector<std::unique_ptr<btMultiBodyJointMotor>> motors_;
  std::vector<BulletJoint> joints_;
  // Forward kinematics' and link velocities' scratch space.
  mutable std::vector<btVector3> link_omega_;
  mutable std::vector<btVector3> link_velocity_;
  mutable btAlignedObjectArray<btQuaternion> world_to_local_;
  mutable btAlignedObjectArray<btVector3> local_origin_;
};

void BulletMultiBodyEngine::AddArticulation(const BenchArticulation& articulation,
                                            const BulletSleep& sleep) {
  const BenchLink& base = articulation.links[0];
  const int link_count = static_cast<int>(articulation.joints.size());
  auto body = std::make_unique<btMultiBody>(link_count, base.mass, ToBullet(base.inertia_diagonal),
                                            /*fixedBase=*/true, /*canSleep=*/!sleep.like_ours);
  Pose world_from_base_com = articulation.world_from_base;
  world_from_base_com.translation = articulation.world_from_base * base.center_of_mass;
  body->setBaseWorldTransform(ToBullet(world_from_base_com));
  for (int j = 0; j < link_count; ++j) {
    const BenchJoint& joint = articulation.joints[j];
    const BenchLink& parent = articulation.links[joint.parent];
    const BenchLink& child = articulation.links[j + 1];
    // Bullet's link frames are the links' centre-of-mass frames, turned as
    // ours; the frames agree at angle 0, so rotParentToThis is identity.
    body->setupRevolute(j, child.mass, ToBullet(child.inertia_diagonal), joint.parent - 1,
                        btQuaternion::getIdentity(), ToBullet(joint.axis),
                        ToBullet(joint.parent_offset - parent.center_of_mass),
                        ToBullet(child.center_of_mass), /*disableParentCollision=*/true);
    BulletJoint bullet_joint;
    bullet_joint.body = body.get();
    bullet_joint.link = j;
    bullet_joint.parent = joint.parent - 1;
    bullet_joint.anchor_from_parent_com = ToBullet(joint.parent_offset - parent.center_of_mass);
    bullet_joint.anchor_from_child_com = ToBullet(-child.center_of_mass);
    joints_.push_back(bullet_joint);
  }
  body->finalizeMultiDof();
  for (int j = 0; j < link_count; ++j) {
    body->setJointPos(j, static_cast<btScalar>(articulation.joints[j].position));
  }
  body->setLinearDamping(0.0);
  body->setAngularDamping(0.0);
  body->setMaxCoordinateVelocity(kMaxCoordinateSpeed);
  body->setHasSelfCollision(false);
  world_.addMultiBody(body.get());
  AddColliders(articulation, body.get());

  const std::size_t first_joint = joints_.size() - static_cast<std::size_t>(link_count);
  for (int j = 0; j < link_count; ++j) {
    if (articulation.motors.empty() || articulation.motors[j].empty()) continue;
    const double max_impulse = articulation.joints[j].effort_limit * time_step_;  // N m s
    motors_.push_back(std::make_unique<btMultiBodyJointMotor>(
        body.get(), j, static_cast<btScalar>(articulation.motors[j].front().velocity),
        static_cast<btScalar>(max_impulse)));
    world_.addMultiBodyConstraint(motors_.back().get());
    joints_[first_joint + j].motor = motors_.back().get();
  }
  multi_bodies_.push_back(std::move(body));
}

// Bullet solves a multibody's joint motors only in the simulation island of
// one of its colliders: a link with motors but no box gets a collider that
// touches nothing (filter group and mask 0), or its motors would never act.
void BulletMultiBodyEngine::AddColliders(const BenchArticulation& articulation, btMultiBody* body) {
  bool motors = false;
  for (const std::vector<MotorPhase>& motor : articulation.motors) motors |= !motor.empty();
  for (int j = 0; j < body->getNumLinks(); ++j) {
    const BenchLink& link = articulation.links[j + 1];
    if (!link.has_box && !motors) continue;
    auto collider = std::make_unique<btMultiBodyLinkCollider>(body, j);
    if (link.has_box) {
      collider->setCollisionShape(bodies_->Box(link.box_size));
      collider->setFriction(static_cast<btScalar>(std::sqrt(link.material.friction)));
      collider->setRestitution(static_cast<btScalar>(link.material.restitution));
      world_.addCollisionObject(collider.get(), btBroadphaseProxy::DefaultFilter,
                                btBroadphaseProxy::AllFilter);
    } else {
      collider->setCollisionShape(&island_marker_);
      world_.addCollisionObject(collider.get(), 0, 0);
    }
    body->getLink(j).m_collider = collider.get();
    colliders_.push_back(std::move(collider));
  }
  body->forwardKinematics(world_to_local_, local_origin_);
  body->updateCollisionObjectWorldTransforms(world_to_local_, local_origin_);
}

// Each link's centre-of-mass frame from the joint positions
// (forwardKinematics), and the joint's anchor as seen from either side.
double BulletMultiBodyEngine::JointAnchorSeparation() const {
  for (const std::unique_ptr<btMultiBody>& body : multi_bodies_) {
    body->forwardKinematics(world_to_local_, local_origin_);
  }
  double separation = 0.0;
  for (const BulletJoint& joint : joints_) {
    const btTransform parent = joint.parent < 0
                                   ? joint.body->getBaseWorldTransform()
                                   : joint.body->getLink(joint.parent).m_cachedWorldTransform;
    const btTransform& child = joint.body->getLink(joint.link).m_cachedWorldTransform;
    const btVector3 gap =
        parent * joint.anchor_from_parent_com - child * joint.anchor_from_child_com;
    separation = std::max(separation, static_cast<double>(gap.length()));
  }
  return separation;
}

// Each link's velocity in its centre-of-mass frame (compTreeLinkVelocities:
// entry 0 is the base, which is fixed) and the height of its centre of mass
// (forwardKinematics).
double BulletMultiBodyEngine::MechanicalEnergy() const {
  double energy = bodies_->MechanicalEnergy();
  for (const std::unique_ptr<btMultiBody>& body : multi_bodies_) {
    body->forwardKinematics(world_to_local_, local_origin_);
    const int links = body->getNumLinks();
    link_omega_.resize(static_cast<std::size_t>(links) + 1);
    link_velocity_.resize(static_cast<std::size_t>(links) + 1);
    body->compTreeLinkVelocities(link_omega_.data(), link_velocity_.data());
    for (int i = 0; i < links; ++i) {
      const btScalar mass = body->getLinkMass(i);
      const btVector3& omega = link_omega_[static_cast<std::size_t>(i) + 1];
      energy += 0.5 * mass * link_velocity_[static_cast<std::size_t>(i) + 1].length2() +
                0.5 * (body->getLinkInertia(i) * omega).dot(omega) +
                mass * kGravity * body->getLink(i).m_cachedWorldTransform.getOrigin().z();
    }
  }
  return energy;
}

}  // namespace

std::unique_ptr<Engine> MakeBulletMultiBodyEngine(const Scene& scene, const BulletSleep& sleep) {
  return std::make_unique<BulletMultiBodyEngine>(scene, sleep);
}

}  // namespace rigid_body_sim::bench
