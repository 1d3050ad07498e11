// The articulations' part of stages 4 and 5 of WorldImpl::Step: their
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
#include <limits>
#include <utility>

#include "physics/articulation/articulation_system.h"
#include "physics/contact/contact_frame.h"
#include "physics/dynamics/integrator.h"

namespace rigid_body_sim::physics {
namespace {

// An island of rigid bodies touching a link is solved with the link's rows
// up to this many bodies (a part a gripper presses on a table, a stack a
// foot stands on, a stack of 16 boxes under a pressing link). A larger one
// keeps the rigid solver for its own contacts: with 64 here, an arm pushing
// through a lattice of 100 boxes (arm_push_100) took 1.23 times its step's
// time, with 16 0.98 of 4's (docs/performance.md, "arm_push_100 against
// bd1bad8 again, and islands of up to 16 bodies").
constexpr std::uint32_t kMostLinkIslandBodies = 16;
// rad or m: how near its limit a joint keeps its limit row.
constexpr double kLimitTolerance = 1e-6;
// Above this many dofs an articulation's rows take M^-1 J^T from the
// articulated-body passes, O(n) each, instead of the dense factor, O(n^3)
// once and O(n^2) per row (bench figures in docs/performance.md).
constexpr int kMostDenseResponseDofs = 24;
// dt lambda above which joint damping is stiff for the free step's RK4.
constexpr double kMaxDampingRate = 0.5;
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
// multipliers), so a dof with mimics gets effort_scale times it. As
// Gazebo's Joint::CheckAndTruncateForce does, an effort that would drive a
// joint already past its speed limit further is not applied: the URDF's
// velocity limit bounds what the joint's actuator drives, not its passive
// motion.
void CommandedEfforts(const ArticulationModel& model, const ArticulationState& state,
                      Eigen::VectorXd* out) {
  Eigen::VectorXd& efforts = *out;
  efforts.setZero(model.joint_dofs);
  for (const ArticulationJoint& joint : model.joints) {
    if (joint.dof < 0 || joint.command.mode != JointCommandMode::kEffort) continue;
    const double effort =
        std::clamp(joint.command.effort, -joint.def.effort_limit, joint.def.effort_limit);
    const double u = state.u[model.base_dofs + joint.dof];
    const double limit = joint.def.velocity_limit;
    if ((effort > 0.0 && u > limit) || (effort < 0.0 && u < -limit)) continue;
    efforts[joint.dof] = joint.effort_scale * effort;
  }
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
  return dt * rate > kMaxDampingRate;
}

// The same test for a model too large for the dense inverse (O(n^3) each
// step: 0.2 s at 999 joints), with lambda_max itself (FastestDampingRate)
// instead of the trace's bound.
bool LargeDampingIsStiff(const ArticulationModel& model, ArticulatedResponse* response, double dt,
                         DampingModeScratch* scratch) {
  return dt * FastestDampingRate(model, dt, response, scratch) > kMaxDampingRate;
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
    // A joint within kLimitTolerance of a limit keeps its row even when its
    // free step leaves it: the contacts solved with it may push it there
    // (a flap on a resting box, tipped by the ground's support, sank 3e-4
    // rad past its limit and was pulled back every third step).
    const double reach = dt * (std::abs(u) + std::abs(u - entry.state.u[column])) + kLimitTolerance;
    auto add = [&](JointRowRole role, double sign, RowKind kind, double target, double bound,
                   double softness) {
      rows->push_back({static_cast<int>(j), column, sign, kind, target, bound, softness, role});
    };
    if (q + dt * u < def.lower + reach)
      add(kLowerLimitRow, 1.0, RowKind::kNormal, (def.lower - q) / dt, 0.0, 0.0);
    if (q + dt * u > def.upper - reach)
      add(kUpperLimitRow, -1.0, RowKind::kNormal, (q - def.upper) / dt, 0.0, 0.0);
    // A motor or servo drives no faster than the joint's speed limit; a limp
    // joint, or one given an effort, is not held to it (as in Gazebo,
    // Bullet and MuJoCo: a limp arm falls freely).
    const bool driven = joint.command.mode == JointCommandMode::kVelocity ||
                        joint.command.mode == JointCommandMode::kPosition;
    if (driven && std::abs(u) > def.velocity_limit) {
      add(u > 0.0 ? kForwardSpeedRow : kBackwardSpeedRow, u > 0.0 ? -1.0 : 1.0, RowKind::kNormal,
          -def.velocity_limit, 0.0, 0.0);
    }
    if (def.friction > 0.0) add(kFrictionRow, 1.0, RowKind::kBounded, 0.0, def.friction * dt, 0.0);
    // Each of the joints the dof moves may exert its own limit.
    const double effort_bound = joint.effort_scale * def.effort_limit * dt;
    if (joint.command.mode == JointCommandMode::kVelocity) {
      const double motor_cap = joint.command.max_effort;
      const double bound = motor_cap > 0.0
                               ? std::min(effort_bound, joint.effort_scale * motor_cap * dt)
                               : effort_bound;
      const double velocity =
          std::clamp(joint.command.velocity, -def.velocity_limit, def.velocity_limit);
      add(kDriveRow, 1.0, RowKind::kBounded, velocity, bound, 0.0);
    } else if (joint.command.mode == JointCommandMode::kPosition) {
      // The implicit spring-damper as a soft row (Catto 2011, "Soft
      // Constraints"): v + gamma lambda = v_cmd - beta (q - q_cmd) / dt with
      // beta = dt k / (dt k + c) and gamma = 1 / (dt (dt k + c)); its steady
      // error under a load tau is tau / k.
      const double kc = dt * gains.stiffness + gains.damping;
      const double beta = dt * gains.stiffness / kc;
      const double gamma = 1.0 / (dt * kc);
      const double target = joint.command.velocity - beta * (q - joint.command.position) / dt;
      add(kDriveRow, 1.0, RowKind::kBounded, target, effort_bound, gamma);
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

std::uint32_t ArticulationSystem::CollisionGroup(const Body& body) const {
  if (body.articulation < 0 || articulations_[body.articulation].model.self_collide) return 0;
  return static_cast<std::uint32_t>(body.articulation) + 1;
}

// The pairs of this step's contact problem with links: every pair with a
// link, and every pair of an island of moving rigid bodies (joined by their
// touching pairs) that touches a link, so that a box a link presses on the
// ground is held by both contacts at once (Baraff 1997, "Rigid Body
// Simulation II", section 8: the resting forces of every contact found
// together). The rest, and islands above kMostLinkIslandBodies, are the
// rigid solver's. Without links the split costs one scan.
void ArticulationSystem::TakeLinkPairs(const std::vector<ShapePairContact*>& touching,
                                       std::vector<ShapePairContact*>* rigid_pairs) {
  rigid_pairs->clear();
  link_pairs_.clear();
  const auto has_link = [this](const ShapePairContact& pair) {
    return bodies_[pair.body_a].articulation >= 0 || bodies_[pair.body_b].articulation >= 0;
  };
  if (std::none_of(touching.begin(), touching.end(),
                   [&](const ShapePairContact* pair) { return has_link(*pair); })) {
    *rigid_pairs = touching;
    return;
  }
  // The islands of moving rigid bodies, joined by their touching pairs (a
  // static or sleeping body joins none: it takes no impulse).
  const auto moves = [this](std::uint32_t index) {
    const Body& body = bodies_[index];
    return body.articulation < 0 && !body.is_static && body.awake && !body.disabled &&
           body.inverse_mass > 0.0;
  };
  UnionFind& islands = link_islands_;
  islands.Reset(bodies_.size());
  for (const ShapePairContact* pair : touching) {
    if (!has_link(*pair) && moves(pair->body_a) && moves(pair->body_b))
      islands.Join(pair->body_a, pair->body_b);
  }
  // Per island root: its moving bodies (counted once each), and whether
  // one of them touches a link.
  std::vector<std::uint32_t>& size = island_sizes_;
  size.assign(bodies_.size(), 0);
  // Bit 0 of a body: counted; bit 1 of a root: its island touches a link.
  std::vector<char>& flags = island_flags_;
  flags.assign(bodies_.size(), 0);
  for (const ShapePairContact* pair : touching) {
    for (const std::uint32_t body : {pair->body_a, pair->body_b}) {
      if (!moves(body) || (flags[body] & 1) != 0) continue;
      flags[body] |= 1;
      ++size[islands.Find(body)];
    }
  }
  for (const ShapePairContact* pair : touching) {
    if (!has_link(*pair)) continue;
    for (const std::uint32_t body : {pair->body_a, pair->body_b}) {
      if (moves(body)) flags[islands.Find(body)] |= 2;
    }
  }
  const auto in_link_island = [&](std::uint32_t body) {
    if (!moves(body)) return false;
    const std::uint32_t root = islands.Find(body);
    return (flags[root] & 2) != 0 && size[root] <= kMostLinkIslandBodies;
  };
  for (ShapePairContact* pair : touching) {
    const bool link =
        has_link(*pair) || in_link_island(pair->body_a) || in_link_island(pair->body_b);
    (link ? link_pairs_ : *rigid_pairs).push_back(pair);
  }
}

// Each row starts from the impulse its joint's row of the same role ended
// the last step with: a held arm's servos carry the same load step after
// step, and from zero the sweeps took tens of passes to find it again.
void ArticulationSystem::AddArticulationRows(std::uint32_t index, int slot,
                                             const std::vector<JointRowSpec>& specs) {
  ArticulationEntry& entry = articulations_[index];
  const int n = entry.model.DofCount();
  entry.joint_row_impulses.resize(entry.model.joints.size() * kJointRowRoles, 0.0);
  for (const JointRowSpec& spec : specs) {
    ConstraintRow row;
    row.articulation = static_cast<int>(index);
    row.joint = spec.joint;
    row.joint_role = spec.role;
    row.impulse = entry.joint_row_impulses[spec.joint * kJointRowRoles + spec.role];
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
  body_impacts_.clear();
  if (articulations_.empty()) return;
  solver_.Reset();
  std::vector<char>& touched = touched_scratch_;
  touched.assign(articulations_.size(), 0);
  for (const ShapePairContact* pair : link_pairs_) {
    for (const std::uint32_t body : {pair->body_a, pair->body_b}) {
      if (bodies_[body].articulation >= 0) touched[bodies_[body].articulation] = 1;
    }
  }
  std::vector<int>& slot = slot_scratch_;
  slot.assign(articulations_.size(), -1);
  contact_only_.assign(articulations_.size(), 0);
  free_stepped_.assign(articulations_.size(), 0);
  for (std::uint32_t i = 0; i < articulations_.size(); ++i) {
    if (!articulations_[i].in_use) continue;
    slot[i] = SetUpArticulation(step, i, touched[i] != 0);
  }
  AddLinkContactRows(step, slot);
  solver_.Solve({kMaxSweeps, kSweepTolerance, step.settings->solver.velocity_tolerance,
                 step.settings->solver.velocity_iterations});
  TakeUnpushedFreeSteps(step, slot);

  for (std::uint32_t i = 0; i < articulations_.size(); ++i) {
    if (slot[i] < 0 || free_stepped_[i] != 0) continue;
    ArticulationEntry& entry = articulations_[i];
    entry.next = Advance(entry.model, entry.state, solver_.articulations()[slot[i]].u, step.dt);
  }
  BounceLinkContacts(step, slot);
  CorrectLinkPenetration(step, slot);
  RecordJointEfforts(step);
  TakeLinkSolveVelocities(step);
}

// Articulation `index`'s free motion, u* = u + dt u' by the ABA. Without
// rows, contacts or stiff damping it takes its free RK4 step at once (and
// gets no solver slot, -1); otherwise it joins the row solve with M + dt B
// and its joint rows, and its solver slot is returned.
int ArticulationSystem::SetUpArticulation(const StepContext& step, std::uint32_t index,
                                          bool touched) {
  ArticulationEntry& entry = articulations_[index];
  ArticulationModel& model = entry.model;
  std::vector<JointRowSpec>& joint_rows = joint_row_scratch_;
  Eigen::VectorXd& acceleration = acceleration_scratch_;
  for (ArticulationLink& link : model.links) {
    link.force = bodies_[link.body].force;
    link.torque = bodies_[link.body].torque;
  }
  Eigen::VectorXd& efforts = efforts_scratch_;
  CommandedEfforts(model, entry.state, &efforts);
  // The last step's end (or a teleport's placement) computed them already.
  ArticulationKinematics& k = entry.kinematics;
  if (!entry.kinematics_current) {
    ComputeKinematics(model, entry.state, &k, KinematicsParts::kPosesAndVelocities);
    entry.kinematics_current = true;
  }
  entry.next_kinematics_current = false;
  ForwardDynamics({model, entry.state, k, step.settings->gravity, efforts, step.dt}, &scratch_,
                  &acceleration);
  Eigen::VectorXd& u_free = free_velocity_scratch_;
  u_free = entry.state.u + step.dt * acceleration;
  JointRowsOf(entry, u_free, step.dt, entry.gains, &joint_rows);
  for (ArticulationJoint& joint : model.joints) {
    joint.effort = joint.dof >= 0 ? efforts[joint.dof] : 0.0;
  }
  const bool damped = AnyJointDamped(model);
  const bool large = model.DofCount() > kMostDenseResponseDofs && ArticulatedBodyApplies(model);
  // scratch_ holds the articulated-body evaluation of u' just made.
  if (large && (damped || touched || !joint_rows.empty())) entry.response.Capture(model, scratch_);
  const bool stiff =
      damped && (large ? LargeDampingIsStiff(model, &entry.response, step.dt, &entry.damping_modes)
                       : DampingIsStiff(model, k, step.dt));
  if (joint_rows.empty() && !touched && !stiff) {
    // Without damping, u* came from the explicit dynamics: the first
    // RK4 stage's u'.
    entry.free_motion.Step({model, entry.state, k, step.settings->gravity, efforts, step.dt,
                            damped ? nullptr : &acceleration},
                           {&entry.next, &entry.next_kinematics});
    entry.next_kinematics_current = true;
    return -1;
  }
  contact_only_[index] = joint_rows.empty() && !stiff ? 1 : 0;
  int slot = -1;
  if (large) {
    slot = solver_.AddArticulation(u_free, &entry.response);
  } else {
    Eigen::MatrixXd mass;
    JointSpaceInertia(model, k, &mass);
    for (const ArticulationJoint& joint : model.joints) {
      if (joint.dof >= 0)
        mass(model.base_dofs + joint.dof, model.base_dofs + joint.dof) +=
            step.dt * joint.def.damping;
    }
    slot = solver_.AddArticulation(u_free, mass);
  }
  AddArticulationRows(index, slot, joint_rows);
  return slot;
}

// An articulation in the solve for its contacts alone (no joint rows, no
// stiff damping) whose rows took no impulse moves freely: it takes the free
// step, RK4 with its energy balance, not the solve's u + dt u' and
// q + dt u+. That explicit step gained energy in a fast spin: a floating arm
// (a 1 kg tip 1.5 m from a 1 kg base), e = 1, gained 18 J of 61 in three
// steps whose only contacts were still apart.
void ArticulationSystem::TakeUnpushedFreeSteps(const StepContext& step,
                                               const std::vector<int>& slot_of_articulation) {
  std::vector<char>& pushed = pushed_scratch_;
  pushed.assign(solver_.articulations().size(), 0);
  for (const ConstraintRow& row : solver_.rows()) {
    if (row.impulse == 0.0) continue;
    for (const RowSide* side : {&row.a, &row.b}) {
      if (side->kind == RowSide::Kind::kArticulation) pushed[side->slot] = 1;
    }
  }
  for (std::uint32_t i = 0; i < articulations_.size(); ++i) {
    const int slot = slot_of_articulation[i];
    if (slot < 0 || contact_only_[i] == 0 || pushed[slot] != 0) continue;
    ArticulationEntry& entry = articulations_[i];
    CommandedEfforts(entry.model, entry.state, &efforts_scratch_);
    entry.free_motion.Step({entry.model, entry.state, entry.kinematics, step.settings->gravity,
                            efforts_scratch_, step.dt},
                           {&entry.next, &entry.next_kinematics});
    entry.next_kinematics_current = true;
    free_stepped_[i] = 1;
  }
}

void ArticulationSystem::RecordJointEfforts(const StepContext& step) {
  // A joint's effort: its command's, its rows' impulses over dt, less its
  // damping; shared with its mimics, each taking its multiplier's part.
  for (ArticulationEntry& entry : articulations_) {
    std::fill(entry.joint_row_impulses.begin(), entry.joint_row_impulses.end(), 0.0);
  }
  for (const ConstraintRow& row : solver_.rows()) {
    if (row.joint < 0) continue;
    ArticulationEntry& entry = articulations_[row.articulation];
    entry.model.joints[row.joint].effort += row.joint_sign * row.impulse / step.dt;
    entry.joint_row_impulses[row.joint * kJointRowRoles + row.joint_role] = row.impulse;
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
    const Vec3 linear_change = solved.linear_velocity - body.linear_velocity;
    const Vec3 solved_momentum = AngularMomentumFor(body, solved.angular_velocity);
    const Vec3 angular_momentum = AngularMomentumFor(body, slot_body.angular_velocity);
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
    // One a link struck within the step drifts t_c v- + (dt - t_c) v+: the
    // trapezoid dt/2 (v_start + v+) gives that with v_start = 2 mean - v+.
    Vec3 mean_linear;
    Vec3 mean_angular;
    if (StruckBodyMeanVelocity(slot_body.body, step.dt, &mean_linear, &mean_angular)) {
      body.start_linear_velocity = 2.0 * mean_linear - slot_body.linear_velocity;
      body.start_angular_momentum = 2.0 * AngularMomentumFor(body, mean_angular) - angular_momentum;
    }
    body.linear_momentum = body.mass * slot_body.linear_velocity;
    body.angular_momentum = angular_momentum;
    body.UpdateDerived();
  }
}

// Stage 5 for the articulations: each takes the state its solve chose, and
// its links follow. A state that is not finite (forces that overflowed) is
// refused: the articulation stays where it was, at rest.
void ArticulationSystem::Move() {
  for (std::uint32_t i = 0; i < articulations_.size(); ++i) {
    ArticulationEntry& entry = articulations_[i];
    if (!entry.in_use) continue;
    const bool sane = StateIsSane(entry.next);
    if (sane) {
      entry.state = entry.next;
    } else {
      entry.state.u.setZero();
      entry.next = entry.state;
    }
    entry.kinematics_current = sane && entry.next_kinematics_current;
    if (entry.kinematics_current) std::swap(entry.kinematics, entry.next_kinematics);
    entry.next_kinematics_current = false;
    PlaceLinks(i, /*restart=*/false);
  }
}

}  // namespace rigid_body_sim::physics
