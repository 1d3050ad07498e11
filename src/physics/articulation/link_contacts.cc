// The contacts of links: their rows in the articulations' solve, the split
// impulse that lifts a link out of what it penetrates, and their reports
// (docs/design.md, "Articulated bodies"); their restitution at the time they
// touch is link_impacts.cc.
#include <algorithm>
#include <array>

#include "physics/articulation/articulation_system.h"
#include "physics/contact/contact_frame.h"

namespace rigid_body_sim::physics {

// d . (velocity of the body's point at `point`) before this step's forces:
// a link's from the joint-space velocity the step starts with, a rigid
// body's from the momenta IntegrateForces started from.
double ArticulationSystem::StartPointVelocity(std::uint32_t index, const Vec3& direction,
                                              const Vec3& point) const {
  const Body& body = bodies_[index];
  const Vec3 r = point - body.position;
  if (body.articulation >= 0) {
    // The link's velocity in the kinematics of the state the step starts from.
    const ArticulationKinematics& k = articulations_[body.articulation].kinematics;
    return direction.dot(k.linear_velocity[body.link] + k.angular_velocity[body.link].cross(r));
  }
  if (body.is_static || !body.awake || body.disabled) return 0.0;
  const Vec3 angular = body.inverse_inertia_world * body.start_angular_momentum;
  return direction.dot(body.start_linear_velocity + angular.cross(r));
}

// A body's sides of the three rows of a contact point, along `directions`:
// a link's through the joints on its path to the base (PointVelocityRows),
// their responses made together (ArticulationSolver::ArticulationSides); a
// rigid body's through its mass and inertia (a static or resting one has
// none).
std::array<RowSide, 3> ArticulationSystem::LinkContactSides(
    const std::vector<int>& slot_of_articulation, std::uint32_t index,
    const std::array<Vec3, 3>& directions, const Vec3& point) {
  const Body& body = bodies_[index];
  if (body.articulation >= 0) {
    const ArticulationEntry& entry = articulations_[body.articulation];
    std::array<Eigen::VectorXd, 3> rows;
    PointVelocityRows(entry.model, entry.kinematics, {body.link, point, directions}, &rows);
    return solver_.ArticulationSides(slot_of_articulation[body.articulation], std::move(rows));
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
  const int slot = solver_.BodySlotOf(body_slot);
  std::array<RowSide, 3> sides;
  for (int r = 0; r < 3; ++r)
    sides[r] = solver_.BodySide(slot, directions[r], point - body.position);
  return sides;
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
                                            const std::vector<int>& slot_of_articulation) {
  link_pair_rows_.assign(link_pairs_.size(), -1);
  link_penetrations_.clear();
  for (std::size_t m = 0; m < link_pairs_.size(); ++m) {
    const ShapePairContact& pair = *link_pairs_[m];
    for (int i = 0; i < pair.manifold.point_count; ++i) {
      const int normal_index = AddLinkPointRows(step, slot_of_articulation, pair, i);
      if (i == 0) link_pair_rows_[m] = normal_index;
    }
  }
}

// Point `i` of a link pair: its normal row (classified as above) and two
// friction rows; returns the normal row's index.
int ArticulationSystem::AddLinkPointRows(const StepContext& step,
                                         const std::vector<int>& slot_of_articulation,
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
  // Side a's rows along the normal and the tangents, side b's against them.
  std::array<RowSide, 3> sides_a = LinkContactSides(
      slot_of_articulation, pair.body_a, {normal, tangent[0], tangent[1]}, point.position_world);
  std::array<RowSide, 3> sides_b = LinkContactSides(
      slot_of_articulation, pair.body_b, {-normal, -tangent[0], -tangent[1]}, point.position_world);
  ConstraintRow normal_row;
  normal_row.kind = RowKind::kNormal;
  normal_row.restitution = restitution;
  normal_row.a = std::move(sides_a[0]);
  normal_row.b = std::move(sides_b[0]);
  const double approach = StartPointVelocity(pair.body_a, normal, point.position_world) +
                          StartPointVelocity(pair.body_b, -normal, point.position_world);
  const double separation = point.separation;
  if (ClassifyContactPoint(separation, approach, solver) == ContactType::kColliding) {
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
  normal_row.impulse = pair.WarmStart(i).normal_impulse;
  const int normal_index = solver_.AddRow(std::move(normal_row));
  if (depth > 0.0) {
    link_penetrations_.emplace_back(normal_index, solver.position_correction * depth / step.dt);
  }
  for (int t = 0; t < 2; ++t) {
    ConstraintRow tangent_row;
    tangent_row.kind = RowKind::kTangent;
    tangent_row.a = std::move(sides_a[1 + t]);
    tangent_row.b = std::move(sides_b[1 + t]);
    tangent_row.normal_row = normal_index;
    tangent_row.friction = friction;
    tangent_row.impulse = pair.WarmStart(i).tangent_impulse[t];
    solver_.AddRow(std::move(tangent_row));
  }
  return normal_index;
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
        slot = pseudo.AddArticulationLike(Eigen::VectorXd::Zero(from.u.size()), from);
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
// their points, as ContactReports::ReportSolved does for the rigid pairs.
void ArticulationSystem::ReportContacts(const StepContext& step, ContactReports* reports) {
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
      ContactReport report = reports->MakeReport(pair, i, tangent, step);
      const bool colliding = normal.colliding && normal.impulse > 0.0;
      report.type = colliding ? ContactType::kColliding : ContactType::kResting;
      reports->Append(report);
    }
  }
}

}  // namespace rigid_body_sim::physics
