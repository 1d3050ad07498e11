// The articulations' part of stages 4 and 5 of ArticulationSystem::Step: their
// motion over the step in joint coordinates, and the rows of their contacts,
// limits, servos, motors and joint friction, solved together
// (docs/design.md, "Articulated bodies").
//
// An articulation with no row this step moves freely by RK4 on
// M(q) u' = Q(q, u), fourth-order exact, split into parts where a whole
// step would gain energy (articulation_free_motion.cc). One with rows takes the
// velocity-level step of the contact problem: u* = u + dt (M + dt B)^-1 Q
// (damping B implicit), then impulses u+ = u* + M^-1 J^T lambda with every
// row's conditions on u+, and q+ = q + dt u+. A row's condition on u+ is one
// on q+, since the joint coordinates are linear in u over the step: a limit
// row u+ >= (lower - q) / dt stops the joint exactly at its limit, without
// bounce.
#include <algorithm>
#include <cmath>

#include "physics/articulation/articulation_system.h"
#include "physics/contact/contact_frame.h"

namespace rigid_body_sim::physics {
namespace {

constexpr int kMaxSweeps = 200;
constexpr double kSweepTolerance = 1e-9;
// The solver's state is refused beyond this size, as the step guard refuses
// a body's (a step's products could overflow).
constexpr double kMaxMagnitude = 1e100;

bool StateIsSane(const ArticulationState& state) {
  return state.base_com.allFinite() && IsFinite(state.base_rotation) && state.q.allFinite() &&
         state.u.allFinite() && state.base_com.cwiseAbs().maxCoeff() < kMaxMagnitude &&
         (state.q.size() == 0 || state.q.cwiseAbs().maxCoeff() < kMaxMagnitude) &&
         (state.u.size() == 0 || state.u.cwiseAbs().maxCoeff() < kMaxMagnitude);
}

Eigen::VectorXd Unit(int size, int index, double sign) {
  Eigen::VectorXd e = Eigen::VectorXd::Zero(size);
  e[index] = sign;
  return e;
}

// The generalized efforts commanded directly, per dof: each joint's
// command clamped to its limit, which its mimics exert too (scaled by their
// multipliers), so a dof with mimics gets effort_scale times it.
Eigen::VectorXd CommandedEfforts(const ArticulationModel& model) {
  Eigen::VectorXd efforts = Eigen::VectorXd::Zero(model.joint_dofs);
  for (const ArticulationJoint& joint : model.joints) {
    if (joint.dof < 0 || joint.command.mode != JointCommandMode::kEffort) continue;
    efforts[joint.dof] =
        joint.effort_scale *
        std::clamp(joint.command.effort, -joint.def.effort_limit, joint.def.effort_limit);
  }
  return efforts;
}

// Whether the free step's explicit RK4 would be unstable or inexact under
// the joints' damping B: its fastest decay rate, the largest eigenvalue of
// M^-1 B, is at most sum_j B_jj (M^-1)_jj (the trace of B^1/2 M^-1 B^1/2,
// whose eigenvalues are those of M^-1 B), and RK4 follows exp(-lambda t)
// closely only while dt lambda stays well inside its stability bound 2.78
// (Hairer and Wanner 1996, "Solving ODEs II", section IV.2). A 0.1 kg pendulum
// whose joint has 3.6e-5 kg m^2 and damping 0.05 N m s decays at
// 1400 1/s: dt lambda = 5.8 at 1/240 s, and its speed grew 100-fold per
// step. Such an articulation takes the implicit velocity-level step. The
// joint-space inertia's norm, compared before, is dominated by a floating
// base's mass and missed it.
bool DampingIsStiff(const ArticulationModel& model, const ArticulationKinematics& kinematics,
                    double dt) {
  constexpr double kMaxRate = 0.5;  // dt lambda
  if (!AnyJointDamped(model)) return false;
  Eigen::MatrixXd mass;
  JointSpaceInertia(model, kinematics, &mass);
  const Eigen::MatrixXd inverse =
      mass.llt().solve(Eigen::MatrixXd::Identity(mass.rows(), mass.cols()));
  double rate = 0.0;
  for (const ArticulationJoint& joint : model.joints) {
    if (joint.dof < 0) continue;
    const int column = model.base_dofs + joint.dof;
    rate += joint.def.damping * inverse(column, column);
  }
  return dt * rate > kMaxRate;
}

// Per movable joint: its limits when the free step would reach them, its
// speed limit when the free step would exceed it, its friction, and its
// command's servo or motor. Efforts commanded directly are in Q already.
void JointRowsOf(const ArticulationEntry& entry, const Eigen::VectorXd& u_free, double dt,
                 const ServoGains& gains, std::vector<JointRowSpec>* rows) {
  rows->clear();
  const ArticulationModel& model = entry.model;
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const ArticulationJoint& joint = model.joints[j];
    if (joint.dof < 0) continue;
    const JointDef& def = joint.def;
    const int column = model.base_dofs + joint.dof;
    const double q = entry.state.q[joint.dof];
    const double u = u_free[column];
    const double reach = dt * (std::abs(u) + std::abs(u - entry.state.u[column])) + 1e-12;
    auto add = [&](double sign, RowKind kind, double target, double bound, double softness) {
      rows->push_back({static_cast<int>(j), column, sign, kind, target, bound, softness});
    };
    if (q + dt * u < def.lower + reach) add(1.0, RowKind::kNormal, (def.lower - q) / dt, 0.0, 0.0);
    if (q + dt * u > def.upper - reach) add(-1.0, RowKind::kNormal, (q - def.upper) / dt, 0.0, 0.0);
    if (std::abs(u) > def.velocity_limit) {
      add(u > 0.0 ? -1.0 : 1.0, RowKind::kNormal, -def.velocity_limit, 0.0, 0.0);
    }
    if (def.friction > 0.0) add(1.0, RowKind::kBounded, 0.0, def.friction * dt, 0.0);
    // Each of the joints the dof moves may exert its own limit.
    const double effort_bound = joint.effort_scale * def.effort_limit * dt;
    if (joint.command.mode == JointCommandMode::kVelocity) {
      add(1.0, RowKind::kBounded, joint.command.velocity, effort_bound, 0.0);
    } else if (joint.command.mode == JointCommandMode::kPosition) {
      // The implicit spring-damper as a soft row (Catto 2011, "Soft
      // Constraints"): v + gamma lambda = v_cmd - beta (q - q_cmd) / dt with
      // beta = dt k / (dt k + c) and gamma = 1 / (dt (dt k + c)); its steady
      // error under a load tau is tau / k.
      const double kc = dt * gains.stiffness + gains.damping;
      const double beta = dt * gains.stiffness / kc;
      const double gamma = 1.0 / (dt * kc);
      const double target = joint.command.velocity - beta * (q - joint.command.position) / dt;
      add(1.0, RowKind::kBounded, target, effort_bound, gamma);
    }
  }
}

}  // namespace

bool ArticulationSystem::SkipsPair(const Body& a, const Body& b) const {
  if (a.articulation < 0 || a.articulation != b.articulation) return false;
  const ArticulationModel& model = articulations_[a.articulation].model;
  if (!model.self_collide) return true;
  const auto joined = [&model](int child, int parent) {
    const int joint = model.links[child].parent_joint;
    return joint >= 0 && model.joints[joint].def.parent_link == parent;
  };
  return joined(a.link, b.link) || joined(b.link, a.link);
}

void ArticulationSystem::TakeLinkPairs(const std::vector<ShapePairContact*>& touching,
                                       std::vector<ShapePairContact*>* rigid_pairs) {
  rigid_pairs->clear();
  link_pairs_.clear();
  for (ShapePairContact* pair : touching) {
    const bool link =
        bodies_[pair->body_a].articulation >= 0 || bodies_[pair->body_b].articulation >= 0;
    (link ? link_pairs_ : *rigid_pairs).push_back(pair);
  }
}

void ArticulationSystem::AddArticulationRows(std::uint32_t index, int slot,
                                             const std::vector<JointRowSpec>& specs) {
  const int n = articulations_[index].model.DofCount();
  for (const JointRowSpec& spec : specs) {
    ConstraintRow row;
    row.articulation = static_cast<int>(index);
    row.joint = spec.joint;
    row.joint_sign = spec.sign;
    row.a = solver_.ArticulationSide(slot, Unit(n, spec.column, spec.sign));
    row.kind = spec.kind;
    row.target = spec.target;
    row.lower = -spec.bound;
    row.upper = spec.bound;
    row.softness = spec.softness;
    solver_.AddRow(std::move(row));
  }
}

// Each articulation's velocity without rows, u* = u + dt (M + dt B)^-1 Q,
// comes from the articulated-body algorithm in O(n) (the damping B
// implicit as an armature). Only an articulation that has rows this step
// (a limit reached, a servo, friction, a contact) or stiff damping builds
// its joint-space inertia M for the row solve, and only one with contacts
// its links' Jacobians; the others take the free RK4 step.
void ArticulationSystem::Solve(const StepContext& step) {
  if (articulations_.empty()) return;
  solver_.Reset();
  std::vector<char> touched(articulations_.size(), 0);
  for (const ShapePairContact* pair : link_pairs_) {
    for (const std::uint32_t body : {pair->body_a, pair->body_b}) {
      if (bodies_[body].articulation >= 0) touched[bodies_[body].articulation] = 1;
    }
  }
  std::vector<int> slot(articulations_.size(), -1);
  std::vector<ArticulationKinematics> kinematics(articulations_.size());
  for (std::uint32_t i = 0; i < articulations_.size(); ++i) {
    if (!articulations_[i].in_use) continue;
    slot[i] = SetUpArticulation(step, i, touched[i] != 0, &kinematics[i]);
  }
  AddLinkContactRows(step, slot, kinematics);
  solver_.Solve(kMaxSweeps, kSweepTolerance);

  for (std::uint32_t i = 0; i < articulations_.size(); ++i) {
    if (slot[i] < 0) continue;
    ArticulationEntry& entry = articulations_[i];
    entry.next = Advance(entry.model, entry.state, solver_.articulations()[slot[i]].u, step.dt);
  }
  BounceLinkContacts(slot);
  CorrectLinkPenetration(step, slot);
  RecordJointEfforts(step);
  TakeLinkSolveVelocities(step);
}

// Articulation `index`'s free motion, u* = u + dt u' by the ABA. Without
// rows, contacts or stiff damping it takes its free RK4 step at once (and
// gets no solver slot, -1); otherwise it joins the row solve with M + dt B
// and its joint rows, and its solver slot is returned.
int ArticulationSystem::SetUpArticulation(const StepContext& step, std::uint32_t index,
                                          bool touched, ArticulationKinematics* kinematics) {
  ArticulationEntry& entry = articulations_[index];
  ArticulationModel& model = entry.model;
  std::vector<JointRowSpec>& joint_rows = joint_row_scratch_;
  Eigen::VectorXd& acceleration = acceleration_scratch_;
  for (ArticulationLink& link : model.links) {
    link.force = bodies_[link.body].force;
    link.torque = bodies_[link.body].torque;
  }
  const Eigen::VectorXd efforts = CommandedEfforts(model);
  ArticulationKinematics& k = *kinematics;
  ComputeKinematics(
      model, entry.state, &k,
      touched ? KinematicsParts::kWithJacobians : KinematicsParts::kPosesAndVelocities);
  ForwardDynamics({model, entry.state, k, step.settings->gravity, efforts, step.dt}, &scratch_,
                  &acceleration);
  const Eigen::VectorXd u_free = entry.state.u + step.dt * acceleration;
  JointRowsOf(entry, u_free, step.dt, entry.gains, &joint_rows);
  for (ArticulationJoint& joint : model.joints) {
    joint.effort = joint.dof >= 0 ? efforts[joint.dof] : 0.0;
  }
  if (joint_rows.empty() && !touched && !DampingIsStiff(model, k, step.dt)) {
    // Without damping, u* came from the explicit dynamics: the first
    // RK4 stage's u'.
    const bool damped = AnyJointDamped(model);
    entry.next = StepFreeMotionBalanced({model, entry.state, step.settings->gravity, efforts,
                                         step.dt, damped ? nullptr : &acceleration},
                                        &entry.free_motion_split);
    return -1;
  }
  Eigen::MatrixXd mass;
  JointSpaceInertia(model, k, &mass);
  for (const ArticulationJoint& joint : model.joints) {
    if (joint.dof >= 0)
      mass(model.base_dofs + joint.dof, model.base_dofs + joint.dof) += step.dt * joint.def.damping;
  }
  const int slot = solver_.AddArticulation(u_free, mass);
  AddArticulationRows(index, slot, joint_rows);
  return slot;
}

void ArticulationSystem::RecordJointEfforts(const StepContext& step) {
  // A joint's effort: its command's, its rows' impulses over dt, less its
  // damping; shared with its mimics, each taking its multiplier's part.
  for (const ConstraintRow& row : solver_.rows()) {
    if (row.joint < 0) continue;
    ArticulationEntry& entry = articulations_[row.articulation];
    entry.model.joints[row.joint].effort += row.joint_sign * row.impulse / step.dt;
  }
  for (ArticulationEntry& entry : articulations_) {
    if (!entry.in_use) continue;
    for (ArticulationJoint& joint : entry.model.joints) {
      if (joint.dof < 0) continue;
      joint.effort -= joint.def.damping * entry.next.u[entry.model.base_dofs + joint.dof];
      joint.effort /= joint.effort_scale;
    }
    for (ArticulationJoint& joint : entry.model.joints) {
      if (joint.dof >= 0) continue;
      joint.effort = joint.def.mimic_multiplier * entry.model.joints[joint.def.mimic_joint].effort;
    }
  }
}

// The rigid bodies that touched links take the link solve's velocities.
void ArticulationSystem::TakeLinkSolveVelocities(const StepContext& step) {
  const std::vector<ArticulationSolver::BodySlot>& slots = solver_.bodies();
  for (std::size_t index = 0; index < slots.size(); ++index) {
    const ArticulationSolver::BodySlot& slot_body = slots[index];
    Body& body = bodies_[slot_body.body];
    if (body.inverse_mass == 0.0 || !body.awake || body.disabled || body.articulation >= 0)
      continue;
    // The velocities of the solve, before any restitution pass.
    const ArticulationSolver::BodySlot& solved =
        solved_bodies_.empty() ? slot_body : solved_bodies_[index];
    const Mat3 rotation = body.orientation.toRotationMatrix();
    auto momentum = [&](const Vec3& angular_velocity) -> Vec3 {
      return rotation * body.inverse_principal_moments.cwiseInverse().asDiagonal() *
             (rotation.transpose() * angular_velocity);
    };
    const Vec3 linear_change = solved.linear_velocity - body.linear_velocity;
    const Vec3 solved_momentum = momentum(solved.angular_velocity);
    const Vec3 angular_momentum = momentum(slot_body.angular_velocity);
    // A change that resting forces can make within the step (at most the
    // collision threshold beyond what gravity gives) is a force over it:
    // the trapezoidal drift keeps it exact, as kinetic friction on a
    // lifted box. A larger one stops an impact, an impulse at the start of
    // the step whose whole change drifts.
    const double resting = step.settings->solver.collision_velocity_threshold +
                           step.settings->time_step * step.settings->gravity.norm();
    if (linear_change.norm() > resting) {
      body.start_linear_velocity += linear_change;
      body.start_angular_momentum += solved_momentum - body.angular_momentum;
    }
    // A bounce of the restitution pass leaves the drift as the solve made it
    // (to where the body touches, as a link's positions), changing only the
    // velocity it ends the step with: dt/2 (v_start + v_end) is unchanged.
    body.start_linear_velocity -= slot_body.linear_velocity - solved.linear_velocity;
    body.start_angular_momentum -= angular_momentum - solved_momentum;
    body.linear_momentum = body.mass * slot_body.linear_velocity;
    body.angular_momentum = angular_momentum;
    body.UpdateDerived();
  }
}

// d . (velocity of the body's point at `point`) before this step's forces:
// a link's from the joint-space velocity the step starts with, a rigid
// body's from the momenta IntegrateForces started from.
double ArticulationSystem::StartPointVelocity(const std::vector<ArticulationKinematics>& kinematics,
                                              std::uint32_t index, const Vec3& direction,
                                              const Vec3& point) const {
  const Body& body = bodies_[index];
  const Vec3 r = point - body.position;
  if (body.articulation >= 0) {
    const JacobianRows& jacobian = kinematics[body.articulation].jacobian[body.link];
    const Eigen::VectorXd& u = articulations_[body.articulation].state.u;
    const Vec3 linear = jacobian.topRows<3>() * u;
    const Vec3 angular = jacobian.bottomRows<3>() * u;
    return direction.dot(linear + angular.cross(r));
  }
  if (body.is_static || !body.awake || body.disabled) return 0.0;
  const Vec3 angular = body.inverse_inertia_world * body.start_angular_momentum;
  return direction.dot(body.start_linear_velocity + angular.cross(r));
}

// One side of a link-contact row along `direction` at `point`: a link's
// through its Jacobian (J_v^T d + J_w^T (r x d)), a rigid body's through
// its mass and inertia (a static or resting one has none).
RowSide ArticulationSystem::LinkContactSide(const LinkRowContext& context, std::uint32_t index,
                                            const Vec3& direction, const Vec3& point) {
  const Body& body = bodies_[index];
  if (body.articulation >= 0) {
    const int articulation_slot = (*context.slot_of_articulation)[body.articulation];
    const JacobianRows& jacobian = (*context.kinematics)[body.articulation].jacobian[body.link];
    const Vec3 r = point - body.position;
    const Eigen::VectorXd row = jacobian.topRows<3>().transpose() * direction +
                                jacobian.bottomRows<3>().transpose() * r.cross(direction);
    return solver_.ArticulationSide(articulation_slot, row);
  }
  ArticulationSolver::BodySlot body_slot;
  body_slot.body = index;
  const bool moves = !body.is_static && body.awake && !body.disabled;
  if (moves) {
    body_slot.linear_velocity = body.linear_velocity;
    body_slot.angular_velocity = body.angular_velocity;
    body_slot.inverse_mass = body.inverse_mass;
    body_slot.inverse_inertia_world = body.inverse_inertia_world;
  }
  return solver_.BodySide(solver_.BodySlotOf(body_slot), direction, point - body.position);
}

// Per point of a pair with a link: a normal row and two friction rows. The
// normal row's target follows the rigid bodies' classification: a point
// touching and closing faster than the collision threshold bounces with
// restitution, v+ >= -e v-; one apart by s may close it within the step,
// v+ >= -s / dt (so nothing passes through a link); one penetrating stops
// sinking, v+ >= 0, and beyond the slop is pushed out by the split impulse
// (CorrectLinkPenetration), which moves positions only. A point is
// classified by v- at the start of the step, before the forces act (Baraff
// 1997, "Rigid Body Simulation II", section 8): a link resting on the
// ground closes at g dt by the end of the free step, above the collision
// threshold, and with e > 0 it would hop every step.
void ArticulationSystem::AddLinkContactRows(const StepContext& step,
                                            const std::vector<int>& slot_of_articulation,
                                            const std::vector<ArticulationKinematics>& kinematics) {
  const LinkRowContext context{&slot_of_articulation, &kinematics};
  link_pair_rows_.assign(link_pairs_.size(), -1);
  link_penetrations_.clear();
  for (std::size_t m = 0; m < link_pairs_.size(); ++m) {
    const ShapePairContact& pair = *link_pairs_[m];
    for (int i = 0; i < pair.manifold.point_count; ++i) {
      const int normal_index = AddLinkPointRows(step, context, pair, i);
      if (i == 0) link_pair_rows_[m] = normal_index;
    }
  }
}

// Point `i` of a link pair: its normal row (classified as above) and two
// friction rows; returns the normal row's index.
int ArticulationSystem::AddLinkPointRows(const StepContext& step, const LinkRowContext& context,
                                         const ShapePairContact& pair, int i) {
  const SolverSettings& solver = step.settings->solver;
  const Body& a = bodies_[pair.body_a];
  const Body& b = bodies_[pair.body_b];
  const Material& material_a = a.shapes[pair.shape_a].material;
  const Material& material_b = b.shapes[pair.shape_b].material;
  const double friction = CombineFriction(material_a.friction, material_b.friction);
  const double restitution = CombineRestitution(material_a.restitution, material_b.restitution);
  const Vec3 normal = pair.manifold.normal_world;
  const std::array<Vec3, 2> tangent = TangentBasis(normal);
  const ContactPoint& point = pair.manifold.points[i];
  ConstraintRow normal_row;
  normal_row.kind = RowKind::kNormal;
  normal_row.a = LinkContactSide(context, pair.body_a, normal, point.position_world);
  normal_row.b = LinkContactSide(context, pair.body_b, -normal, point.position_world);
  const double approach =
      StartPointVelocity(*context.kinematics, pair.body_a, normal, point.position_world) +
      StartPointVelocity(*context.kinematics, pair.body_b, -normal, point.position_world);
  const double separation = point.separation;
  if (separation <= solver.contact_tolerance && approach < -solver.collision_velocity_threshold) {
    normal_row.target = -restitution * approach;
    normal_row.colliding = true;
  } else if (separation > 0.0) {
    normal_row.target = -separation / step.dt;
    if (approach < -solver.collision_velocity_threshold && approach * step.dt < -separation) {
      normal_row.bounce = -restitution * approach;
    }
  } else {
    normal_row.target = 0.0;
  }
  const double depth = -separation - solver.penetration_slop;
  normal_row.impulse = pair.warm_start[i].normal_impulse;
  const int normal_index = solver_.AddRow(std::move(normal_row));
  if (depth > 0.0) {
    link_penetrations_.emplace_back(normal_index, solver.position_correction * depth / step.dt);
  }
  for (int t = 0; t < 2; ++t) {
    ConstraintRow tangent_row;
    tangent_row.kind = RowKind::kTangent;
    tangent_row.a = LinkContactSide(context, pair.body_a, tangent[t], point.position_world);
    tangent_row.b = LinkContactSide(context, pair.body_b, -tangent[t], point.position_world);
    tangent_row.normal_row = normal_index;
    tangent_row.friction = friction;
    tangent_row.impulse = pair.warm_start[i].tangent_impulse[t];
    solver_.AddRow(std::move(tangent_row));
  }
  return normal_index;
}

// Restitution of the link contacts that close within the step. A link has
// no time-of-impact search: a point still apart at the start of the step is
// stopped where it touches by its row, v+ >= -s / dt, and the speed it came
// with is gone by the next step, where it would bounce. So once the
// positions are advanced, the rows of such points that took an impulse are
// solved again, the others' impulses held, for v+ >= -e v-, the speed it
// leaves with (the restitution pass after the position update of Box2D
// v3.0, Catto 2024, contact_solver.c). The body ends the step at the
// contact, moving off at e |v-|, up to one step late against the exact
// rise.
void ArticulationSystem::BounceLinkContacts(const std::vector<int>& slot_of_articulation) {
  std::vector<std::size_t>& bouncing = bouncing_rows_;
  bouncing.clear();
  solved_bodies_.clear();
  std::vector<ConstraintRow>& rows = solver_.rows();
  for (std::size_t k = 0; k < rows.size(); ++k) {
    ConstraintRow& row = rows[k];
    if (row.bounce <= 0.0 || row.impulse <= 0.0) continue;
    row.target = row.bounce;
    row.colliding = true;
    bouncing.push_back(k);
  }
  if (bouncing.empty()) return;
  solved_bodies_ = solver_.bodies();
  solver_.SweepRows(bouncing, kMaxSweeps, kSweepTolerance);
  for (std::uint32_t i = 0; i < articulations_.size(); ++i) {
    const int slot = slot_of_articulation[i];
    if (slot >= 0) articulations_[i].next.u = solver_.articulations()[slot].u;
  }
}

// The split impulse of the link contacts (the rigid bodies' is in
// resting_contact.cc): pseudo velocities from rest, found by projected
// Gauss-Seidel on the penetrating points' normal rows alone with
// J u_p >= position_correction depth / dt, move the articulations' joint
// positions and base by dt u_p and the rigid bodies by their pseudo
// velocities, and change no real velocity. A link spawned into the ground
// is lifted out without a launch speed; pushing through its real velocity
// (Baumgarte) would give it position_correction depth / dt of real speed and, on a spinning
// chain, feed it. The split impulse of Bullet's sequential-impulse solver
// (btSequentialImpulseConstraintSolver), in joint coordinates; the
// projected Gauss-Seidel is Erleben 2007, section 3.
void ArticulationSystem::CorrectLinkPenetration(const StepContext& step,
                                                const std::vector<int>& slot_of_articulation) {
  if (link_penetrations_.empty()) return;
  ArticulationSolver& pseudo = pseudo_solver_;
  pseudo.Reset();
  const std::vector<ArticulationSolver::ArticulationSlot>& velocity_slots = solver_.articulations();
  const std::vector<ArticulationSolver::BodySlot>& velocity_bodies = solver_.bodies();
  std::vector<int> pseudo_slot(velocity_slots.size(), -1);
  auto remap = [&](RowSide side) {
    if (side.kind == RowSide::Kind::kArticulation) {
      int& slot = pseudo_slot[side.slot];
      if (slot < 0) {
        const ArticulationSolver::ArticulationSlot& from = velocity_slots[side.slot];
        slot = pseudo.AddArticulation(Eigen::VectorXd::Zero(from.u.size()), from.mass);
      }
      side.slot = slot;
    } else if (side.kind == RowSide::Kind::kBody) {
      // A rigid body starts from the pseudo velocity its own solve gave it.
      ArticulationSolver::BodySlot body = velocity_bodies[side.slot];
      body.linear_velocity = bodies_[body.body].pseudo_linear_velocity;
      body.angular_velocity = bodies_[body.body].pseudo_angular_velocity;
      side.slot = pseudo.BodySlotOf(body);
    }
    return side;
  };
  for (const auto& [index, target] : link_penetrations_) {
    const ConstraintRow& from = solver_.rows()[index];
    ConstraintRow row;
    row.kind = RowKind::kNormal;
    row.a = remap(from.a);
    row.b = remap(from.b);
    row.target = target;
    pseudo.AddRow(std::move(row));
  }
  // The joints' own rows (motors within their effort, servos, limits,
  // friction, mimics) hold in the correction as in the velocity solve:
  // pushing a box out of a link may turn a joint only as far as a push on
  // it could, not freely past the motor that holds it.
  for (const ConstraintRow& from : solver_.rows()) {
    if (from.articulation < 0 || from.a.kind != RowSide::Kind::kArticulation ||
        pseudo_slot[from.a.slot] < 0) {
      continue;
    }
    ConstraintRow row = from;
    row.a = remap(from.a);
    row.b = remap(from.b);
    row.target = 0.0;
    row.impulse = 0.0;
    row.colliding = false;
    row.bounce = 0.0;
    pseudo.AddRow(std::move(row));
  }
  pseudo.Solve(kMaxSweeps, kSweepTolerance);

  for (std::uint32_t i = 0; i < articulations_.size(); ++i) {
    const int slot = slot_of_articulation[i];
    if (slot < 0 || pseudo_slot[slot] < 0) continue;
    ArticulationEntry& entry = articulations_[i];
    const Eigen::VectorXd velocity = entry.next.u;
    entry.next =
        Advance(entry.model, entry.next, pseudo.articulations()[pseudo_slot[slot]].u, step.dt);
    entry.next.u = velocity;
  }
  for (const ArticulationSolver::BodySlot& slot_body : pseudo.bodies()) {
    Body& body = bodies_[slot_body.body];
    if (body.inverse_mass == 0.0 || !body.awake || body.disabled) continue;
    body.pseudo_linear_velocity = slot_body.linear_velocity;
    body.pseudo_angular_velocity = slot_body.angular_velocity;
  }
}

// Keeps the link pairs' impulses for next step's warm start and reports
// their points, as ReportContacts does for the rigid pairs.
void ArticulationSystem::ReportContacts(const StepContext& step,
                                        std::vector<ContactReport>* contacts,
                                        std::vector<ContactReport>* collision_log) {
  const std::vector<ConstraintRow>& rows = solver_.rows();
  for (std::size_t m = 0; m < link_pairs_.size(); ++m) {
    ShapePairContact& pair = *link_pairs_[m];
    const int first = link_pair_rows_[m];
    pair.previous_count = first < 0 ? 0 : pair.manifold.point_count;
    if (first < 0) continue;
    const std::array<Vec3, 2> tangent = TangentBasis(pair.manifold.normal_world);
    for (int i = 0; i < pair.manifold.point_count; ++i) {
      const ConstraintRow& normal = rows[first + 3 * i];
      const ContactPoint& point = pair.manifold.points[i];
      pair.previous[i] =
          CachedImpulse{point.feature,
                        normal.impulse,
                        {rows[first + 3 * i + 1].impulse, rows[first + 3 * i + 2].impulse},
                        point.position_world};
      const bool touching = point.separation <= step.settings->solver.contact_tolerance;
      if (!touching && normal.impulse <= 0.0) continue;
      ContactReport& report = contacts->emplace_back(world_.MakeReport(pair, i, tangent, step));
      const bool colliding = normal.colliding && normal.impulse > 0.0;
      report.type = colliding ? ContactType::kColliding : ContactType::kResting;
      if (colliding) collision_log->push_back(report);
    }
  }
}

// Stage 5 for the articulations: each takes the state its solve chose, and
// its links follow. A state that is not finite (forces that overflowed) is
// refused: the articulation stays where it was, at rest.
void ArticulationSystem::Move() {
  for (std::uint32_t i = 0; i < articulations_.size(); ++i) {
    ArticulationEntry& entry = articulations_[i];
    if (!entry.in_use) continue;
    if (StateIsSane(entry.next)) {
      entry.state = entry.next;
    } else {
      entry.state.u.setZero();
      entry.next = entry.state;
    }
    PlaceLinks(i, entry.state, /*restart=*/false);
  }
}

}  // namespace rigid_body_sim::physics
