#include "physics/articulation/articulation_solver.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

#include "physics/contact/contact_frame.h"

namespace rigid_body_sim::physics {

void ArticulationSolver::Reset() {
  articulations_.clear();
  bodies_.clear();
  slot_of_body_.clear();
  rows_.clear();
}

int ArticulationSolver::AddArticulation(const Eigen::VectorXd& u, const Eigen::MatrixXd& mass) {
  ArticulationSlot& slot = articulations_.emplace_back();
  slot.u = u;
  slot.mass.emplace(mass);
  return static_cast<int>(articulations_.size()) - 1;
}

int ArticulationSolver::AddArticulation(const Eigen::VectorXd& u,
                                        const Eigen::LLT<Eigen::MatrixXd>& mass) {
  articulations_.push_back(ArticulationSlot{u, mass});
  return static_cast<int>(articulations_.size()) - 1;
}

int ArticulationSolver::AddArticulation(const Eigen::VectorXd& u, ArticulatedResponse* response) {
  ArticulationSlot& slot = articulations_.emplace_back();
  slot.u = u;
  slot.response = response;
  return static_cast<int>(articulations_.size()) - 1;
}

int ArticulationSolver::AddArticulationLike(const Eigen::VectorXd& u,
                                            const ArticulationSlot& like) {
  articulations_.push_back(ArticulationSlot{u, like.mass, like.response});
  return static_cast<int>(articulations_.size()) - 1;
}

int ArticulationSolver::BodySlotOf(const BodySlot& body) {
  if (slot_of_body_.size() <= body.body) slot_of_body_.resize(body.body + 1, -1);
  int& slot = slot_of_body_[body.body];
  if (slot < 0) {
    slot = static_cast<int>(bodies_.size());
    bodies_.push_back(body);
  }
  return slot;
}

namespace {

// One past the last nonzero entry.
Eigen::Index Extent(const Eigen::VectorXd& row) {
  Eigen::Index end = row.size();
  while (end > 0 && row[end - 1] == 0.0) --end;
  return end;
}

}  // namespace

// With the dense factor, a row keeps its full extent, so that its dots sum
// in the order they always did (bit for bit); with the articulated-body
// passes, its zeros past its path are skipped.
RowSide ArticulationSolver::ArticulationSide(int slot, const Eigen::VectorXd& jacobian) const {
  RowSide side;
  side.kind = RowSide::Kind::kArticulation;
  side.slot = slot;
  side.jacobian = jacobian;
  const ArticulationSlot& articulation = articulations_[slot];
  if (articulation.response != nullptr) {
    side.extent = Extent(jacobian);
    articulation.response->Apply(jacobian, side.extent, &side.response);
  } else {
    side.extent = jacobian.size();
    side.response = articulation.mass->solve(jacobian);
  }
  return side;
}

std::array<RowSide, 3> ArticulationSolver::ArticulationSides(
    int slot, std::array<Eigen::VectorXd, 3> jacobians) const {
  const ArticulationSlot& articulation = articulations_[slot];
  std::array<RowSide, 3> sides;
  if (articulation.response == nullptr) {
    for (int r = 0; r < 3; ++r) sides[r] = ArticulationSide(slot, jacobians[r]);
    return sides;
  }
  std::array<Eigen::VectorXd*, 3> responses;
  Eigen::Index extent = 0;
  for (int r = 0; r < 3; ++r) {
    sides[r].kind = RowSide::Kind::kArticulation;
    sides[r].slot = slot;
    sides[r].jacobian = std::move(jacobians[r]);
    sides[r].extent = Extent(sides[r].jacobian);
    extent = std::max(extent, sides[r].extent);
    responses[r] = &sides[r].response;
  }
  articulation.response->ApplyThree({&sides[0].jacobian, &sides[1].jacobian, &sides[2].jacobian},
                                    extent, responses);
  return sides;
}

RowSide ArticulationSolver::BodySide(int slot, const Vec3& direction, const Vec3& lever_arm) const {
  RowSide side;
  const BodySlot& body = bodies_[slot];
  if (body.inverse_mass == 0.0) return side;  // static or asleep: the row sees no velocity
  side.kind = RowSide::Kind::kBody;
  side.slot = slot;
  side.linear = direction;
  side.angular = lever_arm.cross(direction);
  side.linear_response = body.inverse_mass * direction;
  side.angular_response = body.inverse_inertia_world * side.angular;
  return side;
}

int ArticulationSolver::AddRow(ConstraintRow row) {
  rows_.push_back(std::move(row));
  return static_cast<int>(rows_.size()) - 1;
}

// A side's velocity and the impulse's effect on it: the rigid body's
// branch inlined into the sweeps' row updates, an articulation's (a dot over
// its joints) called.
[[gnu::always_inline]] inline double ArticulationSolver::SideVelocity(const RowSide& side) const {
  switch (side.kind) {
    case RowSide::Kind::kArticulation:
      return ArticulationVelocity(side);
    case RowSide::Kind::kBody: {
      const BodySlot& body = bodies_[side.slot];
      return side.linear.dot(body.linear_velocity) + side.angular.dot(body.angular_velocity);
    }
    case RowSide::Kind::kNone:
      break;
  }
  return 0.0;
}

[[gnu::noinline]] double ArticulationSolver::ArticulationVelocity(const RowSide& side) const {
  return side.jacobian.head(side.extent).dot(articulations_[side.slot].u.head(side.extent));
}

double ArticulationSolver::SideResponse(const RowSide& side) const {
  switch (side.kind) {
    case RowSide::Kind::kArticulation:
      return side.jacobian.head(side.extent).dot(side.response.head(side.extent));
    case RowSide::Kind::kBody:
      return side.linear.dot(side.linear_response) + side.angular.dot(side.angular_response);
    case RowSide::Kind::kNone:
      break;
  }
  return 0.0;
}

double ArticulationSolver::RowVelocity(const ConstraintRow& row) const {
  return SideVelocity(row.a) + SideVelocity(row.b);
}

[[gnu::always_inline]] inline void ArticulationSolver::ApplyImpulse(const ConstraintRow& row,
                                                                    double impulse) {
  for (const RowSide* side : {&row.a, &row.b}) {
    if (side->kind == RowSide::Kind::kArticulation) {
      ApplyToArticulation(*side, impulse);
    } else if (side->kind == RowSide::Kind::kBody) {
      BodySlot& body = bodies_[side->slot];
      // As in ContactSolver::ApplyImpulse: a body that does not move keeps
      // its zero velocity even when the impulse overflowed.
      if (body.inverse_mass == 0.0) continue;
      body.linear_velocity += impulse * side->linear_response;
      body.angular_velocity += impulse * side->angular_response;
    }
  }
}

[[gnu::noinline]] void ArticulationSolver::ApplyToArticulation(const RowSide& side,
                                                               double impulse) {
  articulations_[side.slot].u += impulse * side.response;
}

// The two friction rows of a point together: each moves toward zero
// tangential velocity, then the pair is projected onto the disc
// |lambda_t| <= mu lambda_n (a circular Coulomb cone). Returns the largest
// change.
double ArticulationSolver::UpdateFriction(std::size_t k, double* speed) {
  ConstraintRow& t0 = rows_[k];
  ConstraintRow& t1 = rows_[k + 1];
  const double limit = t0.friction * rows_[t0.normal_row].impulse;
  std::array<double, 2> l = {t0.impulse - t0.inverse_mass * RowVelocity(t0),
                             t1.impulse - t1.inverse_mass * RowVelocity(t1)};
  ClampToDisc(limit, &l);
  const double l0 = l[0];
  const double l1 = l[1];
  const double change0 = l0 - t0.impulse;
  const double change1 = l1 - t1.impulse;
  t0.impulse = l0;
  t1.impulse = l1;
  ApplyImpulse(t0, change0);
  ApplyImpulse(t1, change1);
  if (speed != nullptr) {
    *speed = std::max(t0.inverse_mass > 0.0 ? std::abs(change0) / t0.inverse_mass : 0.0,
                      t1.inverse_mass > 0.0 ? std::abs(change1) / t1.inverse_mass : 0.0);
  }
  return std::max(std::abs(change0), std::abs(change1));
}

// Projected Gauss-Seidel on the rows (Cottle, Pang and Stone 1992, "The
// Linear Complementarity Problem", section 5.2; with friction, the
// per-point cone projection of Erleben 2007, section 3): per row,
// lambda <- proj(lambda - (v - target + gamma lambda) / (J M^-1 J^T + gamma)),
// the projection being onto [lower, upper], onto lambda >= 0 for a normal,
// and onto the friction disc for a tangent pair. The warm start's impulses
// are applied first.
int ArticulationSolver::Solve(const SweepLimits& limits) {
  for (ConstraintRow& row : rows_) {
    const double response = SideResponse(row.a) + SideResponse(row.b) + row.softness;
    row.inverse_mass = response > 0.0 ? 1.0 / response : 0.0;
    if (row.kind == RowKind::kBounded) row.impulse = std::clamp(row.impulse, row.lower, row.upper);
    if (row.kind == RowKind::kNormal) row.impulse = std::max(row.impulse, 0.0);
    if (row.impulse != 0.0) ApplyImpulse(row, row.impulse);
  }
  // The rows a sweep updates, a tangent pair by its first row.
  std::vector<std::size_t>& swept = swept_scratch_;
  swept.clear();
  for (std::size_t k = 0; k < rows_.size(); k += rows_[k].kind == RowKind::kTangent ? 2 : 1) {
    swept.push_back(k);
  }
  const bool by_speed = limits.contact_speed > 0.0;
  double held_scale = 0.0;  // N s, the largest impulse of the rows held
  int sweep = 0;
  while (sweep < limits.max_sweeps) {
    ++sweep;
    if (sweep - 1 == limits.rigid_sweeps) held_scale = HoldRigidRows(&swept);
    const SweepChange change = Sweep(swept, by_speed);
    const double scale = std::max(change.scale, held_scale);
    if (change.largest <= limits.tolerance * std::max(scale, 1e-12) &&
        change.fastest <= limits.contact_speed)
      break;
  }
  return sweep;
}

// Drops the rows between rigid bodies alone from `swept`; their impulses
// stay as they are, so the largest of them still sets the sweeps' scale,
// which is returned.
double ArticulationSolver::HoldRigidRows(std::vector<std::size_t>* swept) const {
  double held_scale = 0.0;
  std::size_t kept = 0;
  for (const std::size_t k : *swept) {
    const ConstraintRow& row = rows_[k];
    const bool rigid =
        row.a.kind != RowSide::Kind::kArticulation && row.b.kind != RowSide::Kind::kArticulation;
    if (!rigid) {
      (*swept)[kept++] = k;
    } else if (row.kind != RowKind::kTangent) {
      held_scale = std::max(held_scale, std::abs(row.impulse));
    }
  }
  swept->resize(kept);
  return held_scale;
}

// One projected Gauss-Seidel sweep over `swept` (Cottle, Pang and Stone
// 1992, section 5.2): the largest change of an impulse, the largest velocity
// a contact row's change makes (when judged `by_speed`) and the largest
// impulse of a normal or bounded row.
ArticulationSolver::SweepChange ArticulationSolver::Sweep(const std::vector<std::size_t>& swept,
                                                          bool by_speed) {
  SweepChange result;
  for (const std::size_t k : swept) {
    ConstraintRow& row = rows_[k];
    // A tangent row is always taken with its pair, even one that moves
    // nothing (a cart on a rail across it).
    if (row.kind == RowKind::kTangent) {
      double speed = 0.0;
      const double change = UpdateFriction(k, by_speed ? &speed : nullptr);
      if (by_speed) {
        result.fastest = std::max(result.fastest, speed);
      } else {
        result.largest = std::max(result.largest, change);
      }
      continue;
    }
    const double change = UpdateRow(&row);
    if (by_speed && row.joint < 0) {
      if (row.inverse_mass > 0.0)
        result.fastest = std::max(result.fastest, change / row.inverse_mass);
    } else {
      result.largest = std::max(result.largest, change);
    }
    result.scale = std::max(result.scale, std::abs(row.impulse));
  }
  return result;
}

// lambda <- proj(lambda - (v - target + gamma lambda) / (J M^-1 J^T + gamma)),
// onto lambda >= 0 for a normal, [lower, upper] for a bounded row.
double ArticulationSolver::UpdateRow(ConstraintRow* row) {
  if (row->inverse_mass == 0.0) return 0.0;
  const double velocity = RowVelocity(*row);
  double next =
      row->impulse - row->inverse_mass * (velocity - row->target + row->softness * row->impulse);
  next = row->kind == RowKind::kNormal ? std::max(next, 0.0)
                                       : std::clamp(next, row->lower, row->upper);
  const double change = next - row->impulse;
  row->impulse = next;
  if (change != 0.0) ApplyImpulse(*row, change);
  return std::abs(change);
}

int ArticulationSolver::SweepRows(const std::vector<std::size_t>& rows, int max_sweeps,
                                  double tolerance) {
  int sweep = 0;
  while (sweep < max_sweeps) {
    ++sweep;
    double largest = 0.0;
    double scale = 0.0;
    for (const std::size_t k : rows) {
      assert(rows_[k].kind != RowKind::kTangent);
      largest = std::max(largest, UpdateRow(&rows_[k]));
      scale = std::max(scale, std::abs(rows_[k].impulse));
    }
    if (largest <= tolerance * std::max(scale, 1e-12)) break;
  }
  return sweep;
}

}  // namespace rigid_body_sim::physics
