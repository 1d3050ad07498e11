// The restitution of link contacts at the time they touch (docs/design.md,
// "Articulated bodies", link impacts): the time found on the joints' path
// through the step, the collision impulse there, and the rest of the step
// from it.
#include <algorithm>
#include <cmath>
#include <limits>

#include "physics/articulation/articulation_system.h"
#include "physics/collision/narrow_phase.h"
#include "physics/dynamics/integrator.h"
#include "physics/dynamics/time_of_impact.h"

namespace rigid_body_sim::physics {
namespace {

// m; the time of a link's impact is narrowed until the gap at its legal end
// is within a tenth of this of the surface: 1e-10 s at 1 m/s.
constexpr double kLinkTouchingBand = 1e-9;
// Samples along a link's path at most, so that a link crossing a thin body
// within a step still shows a sample inside it.
constexpr int kMaxLinkPathSamples = 64;

}  // namespace

// Restitution of the link contacts that close within the step, at the
// time they touch. A point still apart at the start of the step is stopped
// where it touches by its row, v+ >= -s / dt. The velocity each
// articulation and rigid body had before those rows stopped it, u- = u -
// M^-1 J^T lambda over their impulses (normal and friction), carries it
// along the step's path, q(t) = q + t u- in joint coordinates and
// x(t) = x + t v-, R(t) = exp(t w-) R for a rigid body; the time t_c its
// first point touches on that path is found from the shapes' own gap
// (LinkPairImpactTime). The rows that took an impulse are then solved
// again, the others' impulses held, for v+ >= -e v-, the speed it leaves
// with (Baraff 1997, "Rigid Body Simulation II", section 8, the collision
// impulse at the time of contact), and the articulation ends the step at
// q + t_c u- + (dt - t_c) u+, as a rigid body does in the sub-step after
// its impact; a rigid body struck by a link drifts the same way
// (StruckBodyMeanVelocity, which both solvers' integrators read).
void ArticulationSystem::BounceLinkContacts(const StepContext& step,
                                            const std::vector<int>& slot_of_articulation) {
  std::vector<std::size_t>& bouncing = bouncing_rows_;
  bouncing.clear();
  solved_bodies_.clear();
  body_impacts_.clear();
  std::vector<ConstraintRow>& rows = solver_.rows();
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (rows[k].bounce > 0.0 && rows[k].impulse > 0.0) bouncing.push_back(k);
  }
  if (bouncing.empty()) return;
  const std::vector<double> impact_times = LinkImpactTimes(step, slot_of_articulation);
  for (const std::size_t k : bouncing) {
    rows[k].target = rows[k].bounce;
    rows[k].colliding = true;
  }
  solved_bodies_ = solver_.bodies();
  solved_articulations_.resize(solver_.articulations().size());
  for (std::size_t slot = 0; slot < solver_.articulations().size(); ++slot)
    solved_articulations_[slot] = solver_.articulations()[slot].u;
  solved_impulses_.clear();
  for (const std::size_t k : bouncing) solved_impulses_.push_back(rows[k].impulse);
  solver_.SweepRows(bouncing, kMaxSweeps, kSweepTolerance);
  CapBounceEnergy(slot_of_articulation);
  for (std::uint32_t i = 0; i < articulations_.size(); ++i) {
    const int slot = slot_of_articulation[i];
    if (slot < 0 || free_stepped_[i] != 0) continue;
    ArticulationEntry& entry = articulations_[i];
    const Eigen::VectorXd& u_after = solver_.articulations()[slot].u;
    const double t_c = impact_times[slot];
    if (t_c < step.dt) {
      const ArticulationState at_impact =
          Advance(entry.model, entry.state, approach_velocities_[slot], t_c);
      entry.next = Advance(entry.model, at_impact, u_after, step.dt - t_c);
    }
    entry.next.u = u_after;
  }
}

// Poisson's restitution can add energy where friction acts (Stronge 1991,
// "Unraveling paradoxical theories for rigid body collisions"; Glocker
// 2013, "Energetic consistency conditions for standard impacts, Part II")
// and where several points of a face are restituted at once, so the
// restitution pass is capped as a rigid collision round is
// (collision_impulses.cc): of its change to the velocities the solve left,
// d = w - u_s, only the share s in [0, 1] is kept that leaves the kinetic
// energy of the articulations and bodies it moved at most what they had
// before the impact, T(u-). T(u_s + s d) = T(u_s) + b s + q s^2 with
// q = T(d) and b = T(u_s + d) - T(u_s) - q. Uncapped, a floating arm
// dropped with e = 1 (link_impact_test FloatingArmGainsNoEnergyFromItsImpacts)
// gained 2.8 J of 61 without friction and 1.2 J with mu = 1.
void ArticulationSystem::CapBounceEnergy(const std::vector<int>& slot_of_articulation) {
  std::vector<int>& articulation_of_slot = articulation_of_slot_;
  articulation_of_slot.assign(solver_.articulations().size(), -1);
  for (std::size_t i = 0; i < articulations_.size(); ++i) {
    if (slot_of_articulation[i] >= 0)
      articulation_of_slot[slot_of_articulation[i]] = static_cast<int>(i);
  }
  std::vector<ArticulationSolver::ArticulationSlot>& slots = solver_.articulations();
  std::vector<ArticulationSolver::BodySlot>& bodies = solver_.bodies();
  // T over the moved slots of velocities chosen per slot by `pick`: 0 the
  // approach, 1 the solve's, 2 after the pass, 3 the pass's change.
  const auto energy = [&](int pick) {
    double sum = 0.0;
    for (std::size_t slot = 0; slot < slots.size(); ++slot) {
      const Eigen::VectorXd& solved = solved_articulations_[slot];
      const int index = articulation_of_slot[slot];
      if (index < 0 || free_stepped_[index] != 0 || slots[slot].u == solved) continue;
      const ArticulationEntry& entry = articulations_[index];
      sum += pick == 0   ? LinkKineticEnergy(entry, approach_velocities_[slot])
             : pick == 1 ? LinkKineticEnergy(entry, solved)
             : pick == 2 ? LinkKineticEnergy(entry, slots[slot].u)
                         : LinkKineticEnergy(entry, slots[slot].u - solved);
    }
    for (std::size_t slot = 0; slot < bodies.size(); ++slot) {
      const ArticulationSolver::BodySlot& after = bodies[slot];
      const ArticulationSolver::BodySlot& solved = solved_bodies_[slot];
      if (after.inverse_mass == 0.0) continue;
      const Body& body = bodies_[after.body];
      const BodyImpact& approach = body_impacts_[slot];
      sum += pick == 0
                 ? BodyKineticEnergy(body, approach.linear_velocity, approach.angular_velocity)
             : pick == 1 ? BodyKineticEnergy(body, solved.linear_velocity, solved.angular_velocity)
             : pick == 2 ? BodyKineticEnergy(body, after.linear_velocity, after.angular_velocity)
                         : BodyKineticEnergy(body, after.linear_velocity - solved.linear_velocity,
                                             after.angular_velocity - solved.angular_velocity);
    }
    return sum;
  };
  const double before = energy(0);
  const double after = energy(2);
  if (after <= before) return;
  const double solved = energy(1);
  const double q = energy(3);
  const double share = RestitutionScale(after - solved - q, q, before - solved);
  for (std::size_t slot = 0; slot < slots.size(); ++slot) {
    const Eigen::VectorXd& u_solved = solved_articulations_[slot];
    slots[slot].u = u_solved + share * (slots[slot].u - u_solved);
  }
  for (std::size_t slot = 0; slot < bodies.size(); ++slot) {
    const ArticulationSolver::BodySlot& from = solved_bodies_[slot];
    bodies[slot].linear_velocity =
        from.linear_velocity + share * (bodies[slot].linear_velocity - from.linear_velocity);
    bodies[slot].angular_velocity =
        from.angular_velocity + share * (bodies[slot].angular_velocity - from.angular_velocity);
  }
  std::vector<ConstraintRow>& rows = solver_.rows();
  for (std::size_t n = 0; n < bouncing_rows_.size(); ++n) {
    ConstraintRow& row = rows[bouncing_rows_[n]];
    row.impulse = solved_impulses_[n] + share * (row.impulse - solved_impulses_[n]);
  }
}

// T = sum_i (m_i v_i^2 + w_i . I_i w_i) / 2 over the links that move, at
// joint velocities u and the step's start pose (the free step's EnergyOf).
double ArticulationSystem::LinkKineticEnergy(const ArticulationEntry& entry,
                                             const Eigen::VectorXd& u) {
  impact_state_ = entry.state;
  impact_state_.u = u;
  ComputeKinematics(entry.model, impact_state_, &impact_kinematics_,
                    KinematicsParts::kPosesAndVelocities);
  return EnergyOf(entry.model, impact_kinematics_, Vec3::Zero()).kinetic;
}

double ArticulationSystem::BodyKineticEnergy(const Body& body, const Vec3& linear_velocity,
                                             const Vec3& angular_velocity) {
  return 0.5 * body.mass * linear_velocity.squaredNorm() +
         0.5 * angular_velocity.dot(AngularMomentumFor(body, angular_velocity));
}

// Per articulation slot, its velocity before the bouncing points' impulses
// (normal and friction), in approach_velocities_; per rigid body slot, its
// own, in body_impacts_.
void ArticulationSystem::FindApproachVelocities() {
  const std::vector<ConstraintRow>& rows = solver_.rows();
  const std::vector<ArticulationSolver::ArticulationSlot>& slots = solver_.articulations();
  approach_velocities_.resize(slots.size());
  for (std::size_t slot = 0; slot < slots.size(); ++slot)
    approach_velocities_[slot] = slots[slot].u;
  body_impacts_.clear();
  for (const ArticulationSolver::BodySlot& body : solver_.bodies())
    body_impacts_.push_back({body.linear_velocity, body.angular_velocity});
  const auto remove_impulse = [&](const ConstraintRow& row) {
    for (const RowSide* side : {&row.a, &row.b}) {
      if (side->kind == RowSide::Kind::kArticulation) {
        approach_velocities_[side->slot] -= row.impulse * side->response;
      } else if (side->kind == RowSide::Kind::kBody) {
        body_impacts_[side->slot].linear_velocity -= row.impulse * side->linear_response;
        body_impacts_[side->slot].angular_velocity -= row.impulse * side->angular_response;
      }
    }
  };
  for (const std::size_t k : bouncing_rows_) {
    remove_impulse(rows[k]);
    for (std::size_t t = k + 1; t <= k + 2 && t < rows.size(); ++t) {
      if (rows[t].kind == RowKind::kTangent && rows[t].normal_row == static_cast<int>(k)) {
        remove_impulse(rows[t]);
      }
    }
  }
}

// J_k w- of one side of a row, at its approach velocities.
double ArticulationSystem::SideApproachVelocity(const RowSide& side) const {
  if (side.kind == RowSide::Kind::kArticulation)
    return side.jacobian.dot(approach_velocities_[side.slot]);
  if (side.kind != RowSide::Kind::kBody) return 0.0;
  const BodyImpact& approach = body_impacts_[side.slot];
  return side.linear.dot(approach.linear_velocity) + side.angular.dot(approach.angular_velocity);
}

// J_k w of one side of a row, at the velocities `fraction` of the way from
// the step's start (before its forces; `start` per articulation slot) to
// the approach velocities (after them, before the bouncing impulses): the
// forces act evenly over the step.
double ArticulationSystem::SideVelocityOnPath(const RowSide& side, double fraction,
                                              const std::vector<Eigen::VectorXd>& start) const {
  if (side.kind == RowSide::Kind::kArticulation) {
    const Eigen::VectorXd& approach = approach_velocities_[side.slot];
    return side.jacobian.dot(start[side.slot] + fraction * (approach - start[side.slot]));
  }
  if (side.kind != RowSide::Kind::kBody) return 0.0;
  const BodyImpact& approach = body_impacts_[side.slot];
  const Body& body = bodies_[solver_.bodies()[side.slot].body];
  const Vec3 start_angular = body.inverse_inertia_world * body.start_angular_momentum;
  const Vec3 linear = body.start_linear_velocity +
                      fraction * (approach.linear_velocity - body.start_linear_velocity);
  const Vec3 angular = start_angular + fraction * (approach.angular_velocity - start_angular);
  return side.linear.dot(linear) + side.angular.dot(angular);
}

// Per articulation slot, the time its first bouncing point touches (dt
// when none is timed), and in approach_velocities_ its velocity before the
// bouncing points' impulses; per rigid body slot the same in body_impacts_.
// A timed point's bounce becomes -e times the speed it strikes with. Reads
// the rows before their bounce targets. A row between two rigid bodies of
// an island a link touches is timed as a link's: the island's pairs are not
// the rigid solver's, so this is their time of impact.
std::vector<double> ArticulationSystem::LinkImpactTimes(
    const StepContext& step, const std::vector<int>& slot_of_articulation) {
  FindApproachVelocities();
  std::vector<ConstraintRow>& rows = solver_.rows();
  const std::size_t slot_count = solver_.articulations().size();
  std::vector<Eigen::VectorXd> start_velocities(slot_count);
  for (std::size_t i = 0; i < articulations_.size(); ++i) {
    const int slot = slot_of_articulation[i];
    if (slot >= 0) start_velocities[slot] = articulations_[i].state.u;
  }
  // The pair of each point's normal row, and each pair's time once found.
  std::vector<int> pair_of_row(rows.size(), -1);
  for (std::size_t m = 0; m < link_pairs_.size(); ++m) {
    const int first = link_pair_rows_[m];
    if (first < 0) continue;
    for (int i = 0; i < link_pairs_[m]->manifold.point_count; ++i)
      pair_of_row[first + 3 * i] = static_cast<int>(m);
  }
  std::vector<double> pair_times(link_pairs_.size(), -1.0);
  std::vector<double> times(slot_count, step.dt);
  for (const std::size_t k : bouncing_rows_) {
    const ConstraintRow& row = rows[k];
    // J u-, m/s
    const double closing = SideApproachVelocity(row.a) + SideApproachVelocity(row.b);
    const double gap = -row.target * step.dt;  // s of the target -s / dt
    if (!(closing < 0.0) || !(gap >= 0.0)) continue;
    double time = std::min(gap / -closing, step.dt);
    const int m = pair_of_row[k];
    if (m >= 0) {
      if (pair_times[m] < 0.0) {
        pair_times[m] = LinkPairImpactTime(step, slot_of_articulation, *link_pairs_[m], -closing);
      }
      if (std::isfinite(pair_times[m])) time = pair_times[m];
    }
    // It strikes with u_c = u(t_c) = u + (t_c / dt) (u- - u) (the forces
    // act evenly over the step) and leaves with w, J w = -e J u_c; the
    // forces then act over the rest of the step, u+ = w + (u- - u_c). So
    // the row's target for u+ is -e J u_c + J (u- - u_c).
    const double closing_at_impact = SideVelocityOnPath(row.a, time / step.dt, start_velocities) +
                                     SideVelocityOnPath(row.b, time / step.dt, start_velocities);
    for (const RowSide* side : {&row.a, &row.b}) {
      if (side->kind == RowSide::Kind::kArticulation) {
        times[side->slot] = std::min(times[side->slot], time);
      } else if (side->kind == RowSide::Kind::kBody) {
        body_impacts_[side->slot].time = std::min(body_impacts_[side->slot].time, time);
      }
    }
    rows[k].bounce =
        std::max(0.0, -row.restitution * closing_at_impact + (closing - closing_at_impact));
  }
  return times;
}

// The pose of body `index`'s frame at time t of the step: a link's on its
// articulation's path q + t u-, a moving rigid body's on x + t v-,
// exp(t w-) R, any other body's where it is (a static one, or one asleep).
Pose ArticulationSystem::BodyPoseOnImpactPath(std::uint32_t index,
                                              const std::vector<int>& slot_of_articulation,
                                              double t) {
  const Body& body = bodies_[index];
  if (body.articulation < 0) {
    const int slot = solver_.SlotOfBody(index);
    if (slot < 0 || solver_.bodies()[slot].inverse_mass == 0.0) return body.WorldFromBody();
    const BodyImpact& approach = body_impacts_[slot];
    const Pose world_from_principal{body.position + t * approach.linear_velocity,
                                    Rotated(body.orientation, t * approach.angular_velocity)};
    return world_from_principal * body.principal_from_body;
  }
  const ArticulationEntry& entry = articulations_[body.articulation];
  const int slot = slot_of_articulation[body.articulation];
  // The kinematics read the velocities too, which the poses do not need.
  impact_state_.u = approach_velocities_[slot];
  AdvanceInto(entry.model, entry.state, impact_state_.u, t, &impact_state_);
  ComputeKinematics(entry.model, impact_state_, &impact_kinematics_,
                    KinematicsParts::kPosesAndVelocities);
  return impact_kinematics_.world_from_link[body.link];
}

// The time a link pair first touches on its articulations' paths through
// the step, q(t) = q + t u-, or +infinity when no sample of the path
// touches (a graze) or the shapes touch already at its start; the linear
// estimate s / (-J u-) times those.
// The joints move on a straight line in q, but a link's points on arcs,
// so the gap is the shapes' own (the narrow phase at q(t)), not the row's
// linear J q: at 100 m/s on a 1 m arm, the linear time put the rebound
// 2e-3 rad off. The path is sampled so that no sample moves the closing
// point more than continuous_fraction of the thinner link, then the
// bracket is narrowed by regula falsi as for rigid bodies (Baraff 1997,
// "Rigid Body Simulation II", section 6, backing up to t_c).
double ArticulationSystem::LinkPairImpactTime(const StepContext& step,
                                              const std::vector<int>& slot_of_articulation,
                                              const ShapePairContact& pair, double closing_speed) {
  const Body& a = bodies_[pair.body_a];
  const Body& b = bodies_[pair.body_b];
  double start_gap = std::numeric_limits<double>::infinity();
  for (int i = 0; i < pair.manifold.point_count; ++i)
    start_gap = std::min(start_gap, pair.manifold.points[i].separation);
  const double cap =
      std::max(start_gap, 0.0) + 2.0 * closing_speed * step.dt + step.settings->contact_margin;
  const auto gap_at = [&](double t) {
    CollideInput input;
    input.a = &a.shapes[pair.shape_a].geometry;
    input.world_from_a = BodyPoseOnImpactPath(pair.body_a, slot_of_articulation, t) *
                         a.shapes[pair.shape_a].body_from_shape;
    input.b = &b.shapes[pair.shape_b].geometry;
    input.world_from_b = BodyPoseOnImpactPath(pair.body_b, slot_of_articulation, t) *
                         b.shapes[pair.shape_b].body_from_shape;
    input.contact_distance = cap;
    return Gap(input);
  };
  ImpactBracket bracket{0.0, gap_at(0.0), -1.0, 0.0};
  // A reused manifold may call apart shapes that touch by its reuse error:
  // no bracket starts there, and the linear estimate stands.
  if (!(bracket.gap_low > 0.0)) return std::numeric_limits<double>::infinity();
  // The thinner of the moving sides (a link, or a rigid body the link solve
  // moves).
  double thickness = std::numeric_limits<double>::infinity();
  for (const std::uint32_t index : {pair.body_a, pair.body_b}) {
    const Body& body = bodies_[index];
    const int slot = body.articulation < 0 ? solver_.SlotOfBody(index) : -1;
    if (body.articulation >= 0 || (slot >= 0 && solver_.bodies()[slot].inverse_mass > 0.0))
      thickness = std::min(thickness, body.thickness);
  }
  const double step_per_sample = step.settings->continuous_fraction * thickness;
  const int samples = static_cast<int>(std::clamp(
      std::ceil(closing_speed * step.dt / step_per_sample), 1.0, double{kMaxLinkPathSamples}));
  for (int k = 1; k <= samples && bracket.high < 0.0; ++k) {
    const double t = step.dt * k / samples;
    const double gap = gap_at(t);
    if (gap <= 0.0) {
      bracket.high = t;
      bracket.gap_high = gap;
    } else {
      bracket.low = t;
      bracket.gap_low = gap;
    }
  }
  if (bracket.high < 0.0) return std::numeric_limits<double>::infinity();
  return NarrowImpactBracket(gap_at, ImpactTarget{0.0, kLinkTouchingBand}, step.dt, bracket).low;
}

bool ArticulationSystem::StruckBodyMeanVelocity(std::uint32_t body, double dt, Vec3* linear,
                                                Vec3* angular) const {
  const int slot = body_impacts_.empty() ? -1 : solver_.SlotOfBody(body);
  if (slot < 0 || !(body_impacts_[slot].time < dt)) return false;
  const BodyImpact& impact = body_impacts_[slot];
  const ArticulationSolver::BodySlot& after = solver_.bodies()[slot];
  const double before = impact.time / dt;
  *linear = before * impact.linear_velocity + (1.0 - before) * after.linear_velocity;
  *angular = before * impact.angular_velocity + (1.0 - before) * after.angular_velocity;
  return true;
}

}  // namespace rigid_body_sim::physics
