#include "physics/contact_solver.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "physics/lcp.h"

namespace rigid_body_sim::physics {
namespace {

// Sweeps of a collision round stop once no impulse changes by more than this
// fraction of the largest impulse.
constexpr double kCollisionConvergence = 1e-10;

// 1 / (1/Ma + 1/Mb + (ra x d).Ia^-1 (ra x d) + (rb x d).Ib^-1 (rb x d)):
// the mass the contact "feels" along d (Baraff, seed 000 slide 34,
// denominator of j).
double EffectiveMass(const SolverBody& a, const SolverBody& b, const Vec3& r_a, const Vec3& r_b,
                     const Vec3& direction) {
  const Vec3 ra_x_d = r_a.cross(direction);
  const Vec3 rb_x_d = r_b.cross(direction);
  const double k = a.inverse_mass + b.inverse_mass + ra_x_d.dot(a.inverse_inertia_world * ra_x_d) +
                   rb_x_d.dot(b.inverse_inertia_world * rb_x_d);
  return k > 0.0 ? 1.0 / k : 0.0;
}

// One scalar mass for both tangent directions, 2 / trace(K_t), where
// K_t(i, i) = 1/Ma + 1/Mb + (ra x t_i).Ia^-1 (ra x t_i) + (rb x t_i).Ib^-1 (rb x t_i).
// An isotropic mass makes each friction update point against the slip, and
// the projection onto the cone then converges to Coulomb's maximal
// dissipation whatever way the tangent basis is turned.
double TangentMass(const SolverBody& a, const SolverBody& b, const Vec3& r_a, const Vec3& r_b,
                   const std::array<Vec3, 2>& tangent) {
  double trace = 0.0;
  for (const Vec3& t : tangent) {
    trace += a.inverse_mass + b.inverse_mass +
             r_a.cross(t).dot(a.inverse_inertia_world * r_a.cross(t)) +
             r_b.cross(t).dot(b.inverse_inertia_world * r_b.cross(t));
  }
  return trace > 0.0 ? 2.0 / trace : 0.0;
}

// Projects the tangential impulse onto the disc |t| <= limit (a circular
// friction cone, so there is no directional bias).
void ClampToDisc(double limit, std::array<double, 2>* tangent) {
  // sqrt of the sum of squares: hypot's care for overflow costs more than
  // the whole row update, and impulses are nowhere near 1e150.
  const double norm_squared = (*tangent)[0] * (*tangent)[0] + (*tangent)[1] * (*tangent)[1];
  if (norm_squared > limit * limit) {
    const double norm = std::sqrt(norm_squared);
    const double scale = norm > 0.0 ? limit / norm : 0.0;
    (*tangent)[0] *= scale;
    (*tangent)[1] *= scale;
  }
}

}  // namespace

std::array<Vec3, 2> TangentBasis(const Vec3& normal) {
  const Vec3 helper = std::abs(normal.x()) < 0.57 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 t1 = normal.cross(helper).normalized();
  return {t1, normal.cross(t1)};
}

double CombineRestitution(double restitution_a, double restitution_b) {
  return std::max(restitution_a, restitution_b);
}

double CombineFriction(double friction_a, double friction_b) {
  return std::sqrt(friction_a * friction_b);
}

void ContactSolver::Reset(const SolverSettings& settings, double time_step,
                          std::size_t body_count) {
  assert(time_step > 0.0);
  settings_ = settings;
  time_step_ = time_step;
  // Sized, not cleared: World loads the bodies the contacts reach.
  bodies_.resize(body_count);
  manifolds_.clear();
}

void ContactSolver::Prepare() {
  for (SolverManifold& manifold : manifolds_) {
    manifold.tangent_world = TangentBasis(manifold.normal_world);
    for (int i = 0; i < manifold.point_count; ++i) {
      SolverPoint& point = manifold.points[i];
      point.normal_velocity_before = NormalVelocity(manifold, point);
      const double epsilon = settings_.collision_velocity_threshold;
      if (point.separation > settings_.contact_tolerance) {
        // Apart now, but an inelastic point (a speculative row) whose
        // approach closes the gap within the step collides in this step.
        const bool meets = manifold.restitution <= 0.0 && point.normal_velocity_before < -epsilon &&
                           -point.normal_velocity_before * time_step_ >= point.separation;
        point.type = meets ? ContactType::kColliding : ContactType::kSeparating;
      } else if (point.normal_velocity_before < -epsilon) {
        point.type = ContactType::kColliding;
      } else if (point.normal_velocity_before <= epsilon) {
        point.type = ContactType::kResting;
      } else {
        point.type = ContactType::kSeparating;
      }
    }
  }
}

Vec3 ContactSolver::RelativeVelocity(const SolverManifold& manifold,
                                     const SolverPoint& point) const {
  const SolverBody& a = bodies_[manifold.body_a];
  const SolverBody& b = bodies_[manifold.body_b];
  return a.linear_velocity + a.angular_velocity.cross(point.r_a) - b.linear_velocity -
         b.angular_velocity.cross(point.r_b);
}

// v_r = n . (pa' - pb'), pa' = va + wa x ra (Baraff, seed 000 slide 19).
double ContactSolver::NormalVelocity(const SolverManifold& manifold,
                                     const SolverPoint& point) const {
  return manifold.normal_world.dot(RelativeVelocity(manifold, point));
}

// P_a += J, L_a += r_a x J; the opposite on B (Baraff, seed 000 slide 34).
void ContactSolver::ApplyImpulse(const SolverManifold& manifold, const SolverPoint& point,
                                 const Vec3& impulse_world) {
  SolverBody& a = bodies_[manifold.body_a];
  SolverBody& b = bodies_[manifold.body_b];
  a.linear_velocity += a.inverse_mass * impulse_world;
  a.angular_velocity += Multiply(a.inverse_inertia_world, point.r_a.cross(impulse_world));
  b.linear_velocity -= b.inverse_mass * impulse_world;
  b.angular_velocity -= Multiply(b.inverse_inertia_world, point.r_b.cross(impulse_world));
}

double ContactSolver::CollisionSweep(const std::vector<std::pair<int, int>>& active,
                                     std::vector<double>* normal,
                                     std::vector<std::array<double, 2>>* tangent) {
  double largest_change = 0.0;
  for (std::size_t k = 0; k < active.size(); ++k) {
    SolverManifold& manifold = manifolds_[active[k].first];
    const SolverPoint& point = manifold.points[active[k].second];
    // Compression: drive v_r to zero with a non-negative impulse.
    const double v_r = NormalVelocity(manifold, point);
    const double old_normal = (*normal)[k];
    (*normal)[k] = std::max(0.0, old_normal - point.normal_mass * v_r);
    const double normal_change = (*normal)[k] - old_normal;
    ApplyImpulse(manifold, point, normal_change * manifold.normal_world);
    largest_change = std::max(largest_change, std::abs(normal_change));
    if (manifold.friction <= 0.0) continue;
    // Coulomb: stick if |j_t| <= mu j_n, otherwise slide on the cone.
    const Vec3 v = RelativeVelocity(manifold, point);
    const std::array<double, 2> old_tangent = (*tangent)[k];
    const Eigen::Vector2d change =
        -point.tangent_mass *
        Eigen::Vector2d(manifold.tangent_world[0].dot(v), manifold.tangent_world[1].dot(v));
    (*tangent)[k][0] += change[0];
    (*tangent)[k][1] += change[1];
    ClampToDisc(manifold.friction * (*normal)[k], &(*tangent)[k]);
    const double dt0 = (*tangent)[k][0] - old_tangent[0];
    const double dt1 = (*tangent)[k][1] - old_tangent[1];
    ApplyImpulse(manifold, point,
                 dt0 * manifold.tangent_world[0] + dt1 * manifold.tangent_world[1]);
    largest_change = std::max({largest_change, std::abs(dt0), std::abs(dt1)});
  }
  return largest_change;
}

// The compression LCP of a collision round: w = A j + b >= 0, j >= 0,
// j . w = 0, with A_ik = n_i . (velocity change at point i per unit impulse
// n_k at point k) = J_i M^-1 J_k^T and b_i = v_r,i. Solved by pivoting
// (lcp.h), so frictionless collisions are exact: with e = 1 no energy is
// lost to an unconverged iteration.
bool ContactSolver::SolveCompressionExactly(const std::vector<std::pair<int, int>>& active,
                                            std::vector<double>* normal) {
  const int n = static_cast<int>(active.size());
  Eigen::MatrixXd a(n, n);
  Eigen::VectorXd b(n);
  for (int k = 0; k < n; ++k) {
    const SolverManifold& column_manifold = manifolds_[active[k].first];
    const SolverPoint& column_point = column_manifold.points[active[k].second];
    const Vec3& n_k = column_manifold.normal_world;
    const SolverBody& body_a = bodies_[column_manifold.body_a];
    const SolverBody& body_b = bodies_[column_manifold.body_b];
    // Velocity changes of the column's two bodies per unit impulse.
    const Vec3 dv_a = body_a.inverse_mass * n_k;
    const Vec3 dw_a = body_a.inverse_inertia_world * column_point.r_a.cross(n_k);
    const Vec3 dv_b = -body_b.inverse_mass * n_k;
    const Vec3 dw_b = -(body_b.inverse_inertia_world * column_point.r_b.cross(n_k));
    for (int i = 0; i < n; ++i) {
      const SolverManifold& row_manifold = manifolds_[active[i].first];
      const SolverPoint& row_point = row_manifold.points[active[i].second];
      Vec3 relative = Vec3::Zero();
      auto add = [&](std::uint32_t body, const Vec3& r, double sign) {
        if (body == column_manifold.body_a) relative += sign * (dv_a + dw_a.cross(r));
        if (body == column_manifold.body_b) relative += sign * (dv_b + dw_b.cross(r));
      };
      add(row_manifold.body_a, row_point.r_a, 1.0);
      add(row_manifold.body_b, row_point.r_b, -1.0);
      a(i, k) = row_manifold.normal_world.dot(relative);
    }
    b[k] = NormalVelocity(column_manifold, column_point);
  }
  const Result<LcpSolution> solution = SolveLcpLemke(a, b);
  if (!solution.ok()) return false;
  for (int k = 0; k < n; ++k) {
    const SolverManifold& manifold = manifolds_[active[k].first];
    const SolverPoint& point = manifold.points[active[k].second];
    (*normal)[k] = solution->f[k];
    ApplyImpulse(manifold, point, solution->f[k] * manifold.normal_world);
  }
  return true;
}

// The effective masses of every point, for the collision rounds; the
// resting solve makes its own from the angular responses (BuildRestingRows).
void ContactSolver::ComputeMasses() {
  for (SolverManifold& manifold : manifolds_) {
    const SolverBody& a = bodies_[manifold.body_a];
    const SolverBody& b = bodies_[manifold.body_b];
    for (int i = 0; i < manifold.point_count; ++i) {
      SolverPoint& point = manifold.points[i];
      point.normal_mass = EffectiveMass(a, b, point.r_a, point.r_b, manifold.normal_world);
      point.tangent_mass = TangentMass(a, b, point.r_a, point.r_b, manifold.tangent_world);
    }
  }
}

void ContactSolver::ResolveCollisions() {
  const double epsilon = settings_.collision_velocity_threshold;
  std::vector<std::pair<int, int>> active;
  std::vector<double> normal;
  std::vector<std::array<double, 2>> tangent;
  velocities_changed_ = false;
  for (int round = 0; round < settings_.max_collision_rounds; ++round) {
    active.clear();
    for (int m = 0; m < static_cast<int>(manifolds_.size()); ++m) {
      const SolverManifold& manifold = manifolds_[m];
      for (int i = 0; i < manifold.point_count; ++i) {
        const SolverPoint& point = manifold.points[i];
        if (point.separation > settings_.contact_tolerance) continue;
        // Nothing has acted before the first round: Prepare's v_r holds.
        const double v_r =
            round == 0 ? point.normal_velocity_before : NormalVelocity(manifold, point);
        if (v_r < -epsilon) active.emplace_back(m, i);
      }
    }
    // A round of only inelastic points (e = 0) is the resting solve's LCP
    // with v_r+ >= 0, which that solve meets for them together with every
    // resting point; only restitution needs rounds of its own.
    const bool elastic = std::any_of(active.begin(), active.end(), [&](const auto& entry) {
      return manifolds_[entry.first].restitution > 0.0;
    });
    if (!elastic) return;
    velocities_changed_ = true;
    if (round == 0) ComputeMasses();
    normal.assign(active.size(), 0.0);
    tangent.assign(active.size(), {0.0, 0.0});
    bool frictionless = true;
    for (const auto& [m, i] : active) frictionless &= manifolds_[m].friction <= 0.0;
    const bool exact = static_cast<int>(active.size()) <= settings_.max_pivoting_points &&
                       SolveCompressionExactly(active, &normal);
    for (int sweep = 0; sweep < settings_.collision_iterations && !(exact && frictionless);
         ++sweep) {
      const double change = CollisionSweep(active, &normal, &tangent);
      double largest = 0.0;
      for (double j : normal) largest = std::max(largest, j);
      if (change <= kCollisionConvergence * largest) break;
    }
    // The last round is perfectly inelastic, which ends the rounds.
    const bool last_round = round + 1 == settings_.max_collision_rounds;
    for (std::size_t k = 0; k < active.size(); ++k) {
      SolverManifold& manifold = manifolds_[active[k].first];
      SolverPoint& point = manifold.points[active[k].second];
      const double restitution = last_round ? 0.0 : manifold.restitution;
      ApplyImpulse(manifold, point, restitution * normal[k] * manifold.normal_world);
      point.collision_impulse += (1.0 + restitution) * normal[k];
      point.type = ContactType::kColliding;
    }
  }
}

void ContactSolver::RecordStartVelocities() {
  for (SolverManifold& manifold : manifolds_) {
    for (int i = 0; i < manifold.point_count; ++i) {
      SolverPoint& point = manifold.points[i];
      point.normal_velocity_start =
          velocities_changed_ ? NormalVelocity(manifold, point) : point.normal_velocity_before;
    }
  }
}

// Rows of the resting solve: the touching points, and the speculative ones
// of inelastic pairs, copied into one array in manifold order so that a
// sweep walks memory once.
void ContactSolver::BuildRestingRows() {
  const double inverse_dt = 1.0 / time_step_;
  rows_.clear();
  for (SolverManifold& manifold : manifolds_) {
    const SolverBody& a = bodies_[manifold.body_a];
    const SolverBody& b = bodies_[manifold.body_b];
    for (int i = 0; i < manifold.point_count; ++i) {
      SolverPoint& point = manifold.points[i];
      // A point that is not touching yet is left to the time-of-impact
      // search, so that its collision keeps its approach speed and
      // restitution, unless the manifold has none to keep (e = 0): then it
      // is a speculative row that lets the gap close within the step but
      // not overshoot, so a face landing on a face is held at all its
      // corners at once instead of tipping about the first one to touch,
      // and a column pushed from above is held at its near gaps too.
      const bool touching = point.separation <= settings_.contact_tolerance;
      if (!touching && manifold.restitution > 0.0) {
        point.normal_impulse = 0.0;
        point.tangent_impulse = {0.0, 0.0};
        continue;
      }
      RestingRow& row = rows_.emplace_back();
      row.body_a = manifold.body_a;
      row.body_b = manifold.body_b;
      row.normal = manifold.normal_world;
      row.tangent = manifold.tangent_world;
      row.r_a = point.r_a;
      row.r_b = point.r_b;
      row.friction = manifold.friction;
      row.inverse_mass_a = a.inverse_mass;
      row.inverse_mass_b = b.inverse_mass;
      const std::array<Vec3, 3> directions{row.normal, row.tangent[0], row.tangent[1]};
      // The responses, and from them the effective masses of EffectiveMass
      // and TangentMass: 1/Ma + 1/Mb + sum over A, B of (r x d).I^-1 (r x d).
      std::array<double, 3> inverse_mass_along{};
      for (int k = 0; k < 3; ++k) {
        const Vec3 ra_x_d = point.r_a.cross(directions[k]);
        const Vec3 rb_x_d = point.r_b.cross(directions[k]);
        row.angular_a[k] = a.inverse_inertia_world * ra_x_d;
        row.angular_b[k] = b.inverse_inertia_world * rb_x_d;
        inverse_mass_along[k] = a.inverse_mass + b.inverse_mass + ra_x_d.dot(row.angular_a[k]) +
                                rb_x_d.dot(row.angular_b[k]);
      }
      row.normal_mass = inverse_mass_along[0] > 0.0 ? 1.0 / inverse_mass_along[0] : 0.0;
      const double trace = inverse_mass_along[1] + inverse_mass_along[2];
      row.tangent_mass = trace > 0.0 ? 2.0 / trace : 0.0;
      // K t_k . n: the tangential velocity a unit normal impulse adds, with
      // K = (1/Ma + 1/Mb) 1 - [ra]x Ia^-1 [ra]x - [rb]x Ib^-1 [rb]x. The
      // normal part is 1/Ma + 1/Mb times t.n = 0.
      for (int k = 0; k < 2; ++k) {
        row.normal_coupling[k] = point.r_a.cross(row.tangent[k]).dot(row.angular_a[0]) +
                                 point.r_b.cross(row.tangent[k]).dot(row.angular_b[0]);
      }
      // A touching point: the trapezoidal drift dt/2 (v_start + v_end) must
      // not close the gap. A speculative point: a body its row pushes drifts
      // dt v_end (step_solver.cc), which must close the gap exactly at most;
      // one it does not push and that still overshoots was apart at the
      // start, so the time-of-impact search backs it up.
      const double gap = std::max(point.separation, 0.0);
      row.target = std::min(0.0, touching ? -2.0 * gap * inverse_dt - point.normal_velocity_start
                                          : -gap * inverse_dt);
      row.depth = -point.separation - settings_.penetration_slop;
      row.normal_impulse = point.normal_impulse;
      row.tangent_impulse = point.tangent_impulse;
      row.point = &point;
    }
  }
}

namespace {

// A run partners with one of at most this many runs after it that are not
// scheduled yet.
constexpr int kPartnerWindow = 4;
// Marks a body the solve cannot move (static or asleep): rows that share
// only such bodies are independent.
constexpr std::uint32_t kFixedBody = std::numeric_limits<std::uint32_t>::max();

// Whether the solve can move a body: static and sleeping ones have zero
// inverse mass and inertia.
bool Moves(const SolverBody& body) {
  return body.inverse_mass != 0.0 || (body.inverse_inertia_world.array() != 0.0).any();
}

// The velocities of the two bodies of one run of rows, held in locals while
// the run's rows update them, so that one row's result reaches the next in
// registers instead of through memory.
struct RunVelocities {
  Vec3 linear_a;
  Vec3 angular_a;
  Vec3 linear_b;
  Vec3 angular_b;
};

// The two bodies' real velocities, or with kPseudo the split impulse's.
template <bool kPseudo>
RunVelocities LoadRun(const SolverBody& a, const SolverBody& b) {
  if constexpr (kPseudo) {
    return {a.pseudo_linear_velocity, a.pseudo_angular_velocity, b.pseudo_linear_velocity,
            b.pseudo_angular_velocity};
  } else {
    return {a.linear_velocity, a.angular_velocity, b.linear_velocity, b.angular_velocity};
  }
}

template <bool kPseudo>
void StoreRun(const RunVelocities& velocities, SolverBody* a, SolverBody* b) {
  if constexpr (kPseudo) {
    a->pseudo_linear_velocity = velocities.linear_a;
    a->pseudo_angular_velocity = velocities.angular_a;
    b->pseudo_linear_velocity = velocities.linear_b;
    b->pseudo_angular_velocity = velocities.angular_b;
  } else {
    a->linear_velocity = velocities.linear_a;
    a->angular_velocity = velocities.angular_a;
    b->linear_velocity = velocities.linear_b;
    b->angular_velocity = velocities.angular_b;
  }
}

// Adds the impulse (normal, tangent 0, tangent 1) components of a row to its
// bodies: dv = +-J / M, dw = +-sum_k j_k I^-1 (r x d_k) with the responses
// I^-1 (r x d_k) made once per step, so a sweep does no 3x3 product.
void AddRowImpulse(const RestingRow& row, const Vec3& components, RunVelocities* velocities) {
  const Vec3 impulse_world =
      components[0] * row.normal + components[1] * row.tangent[0] + components[2] * row.tangent[1];
  velocities->linear_a += row.inverse_mass_a * impulse_world;
  velocities->angular_a += components[0] * row.angular_a[0] + components[1] * row.angular_a[1] +
                           components[2] * row.angular_a[2];
  velocities->linear_b -= row.inverse_mass_b * impulse_world;
  velocities->angular_b -= components[0] * row.angular_b[0] + components[1] * row.angular_b[1] +
                           components[2] * row.angular_b[2];
}

// One projected Gauss-Seidel update of a point: the relative velocity is
// read once; the friction impulse is projected onto the disc
// |f_t| <= mu f_n, the normal velocity is corrected by what that change
// adds (normal_coupling, n.K t = t.K n), the normal impulse is projected
// onto f >= 0, and the sum of the three changes is applied once. Returns
// |v - v_previous sweep|^2, m^2/s^2.
double UpdateRestingRow(RestingRow* row, RunVelocities* velocities) {
  const Vec3 v = velocities->linear_a + velocities->angular_a.cross(row->r_a) -
                 velocities->linear_b - velocities->angular_b.cross(row->r_b);
  const double change_squared = (v - row->last_velocity).squaredNorm();
  row->last_velocity = v;
  Vec3 change = Vec3::Zero();  // normal, tangent 0, tangent 1
  double normal_velocity = row->normal.dot(v);
  if (row->friction > 0.0) {
    const std::array<double, 2> old_tangent = row->tangent_impulse;
    for (int k = 0; k < 2; ++k) {
      row->tangent_impulse[k] -= row->tangent_mass * row->tangent[k].dot(v);
    }
    ClampToDisc(row->friction * row->normal_impulse, &row->tangent_impulse);
    for (int k = 0; k < 2; ++k) {
      change[k + 1] = row->tangent_impulse[k] - old_tangent[k];
      normal_velocity += row->normal_coupling[k] * change[k + 1];
    }
  }
  const double old_normal = row->normal_impulse;
  row->normal_impulse =
      std::max(0.0, old_normal + row->normal_mass * (row->target - normal_velocity));
  change[0] = row->normal_impulse - old_normal;
  AddRowImpulse(*row, change, velocities);
  return change_squared;
}

// One update of a point's split impulse: the pseudo velocity along the
// normal is driven to position_correction depth / dt, with a non-negative
// impulse.
void UpdatePseudoRow(double position_correction, double inverse_dt, RestingRow* row,
                     RunVelocities* velocities) {
  if (row->depth <= 0.0) return;
  const double target = position_correction * row->depth * inverse_dt;
  const double v_r = row->normal.dot(velocities->linear_a + velocities->angular_a.cross(row->r_a) -
                                     velocities->linear_b - velocities->angular_b.cross(row->r_b));
  const double old_impulse = row->pseudo_impulse;
  row->pseudo_impulse = std::max(0.0, old_impulse + row->normal_mass * (target - v_r));
  const double change = row->pseudo_impulse - old_impulse;
  velocities->linear_a += (row->inverse_mass_a * change) * row->normal;
  velocities->angular_a += change * row->angular_a[0];
  velocities->linear_b -= (row->inverse_mass_b * change) * row->normal;
  velocities->angular_b -= change * row->angular_b[0];
}

// The update of a sweep over the real velocities (UpdateRestingRow) or, with
// kPseudo, the split impulse's (UpdatePseudoRow, which returns 0).
template <bool kPseudo>
double UpdateRow(double position_correction, double inverse_dt, RestingRow* row,
                 RunVelocities* velocities) {
  if constexpr (kPseudo) {
    UpdatePseudoRow(position_correction, inverse_dt, row, velocities);
    return 0.0;
  } else {
    return UpdateRestingRow(row, velocities);
  }
}

}  // namespace

// One sweep over the schedule, the two runs of a task alternately: the
// resting rows' Gauss-Seidel update on the real velocities, which skips the
// runs of converged islands and records each island's largest
// |v - v_previous sweep|^2, or with kPseudo the split impulse's on the
// pseudo velocities, over every island. Flattened: with any update left a
// call, a run's velocities stay in memory and the sweep takes 30 % longer.
template <bool kPseudo>
[[gnu::flatten]] void ContactSolver::SweepSchedule() {
  const double correction = settings_.position_correction;
  const double inverse_dt = 1.0 / time_step_;
  for (const SweepTask& task : schedule_) {
    std::uint32_t first_begin = task.first_begin;
    std::uint32_t first_end = task.first_end;
    std::uint32_t first_island = task.first_island;
    std::uint32_t second_begin = task.second_begin;
    std::uint32_t second_end = task.second_end;
    if constexpr (!kPseudo) {
      if (islands_[task.second_island].converged) second_end = second_begin;
      if (islands_[first_island].converged) {
        first_begin = second_begin;
        first_end = second_end;
        first_island = task.second_island;
        second_end = second_begin;
      }
      if (first_begin == first_end) continue;
    }
    const bool paired = second_begin != second_end;
    SolverBody& first_a = bodies_[rows_[first_begin].body_a];
    SolverBody& first_b = bodies_[rows_[first_begin].body_b];
    // An unpaired task loads its first run's bodies as the second run's too;
    // the empty second run never updates or stores them.
    const std::uint32_t second_row = paired ? second_begin : first_begin;
    SolverBody& second_a = bodies_[rows_[second_row].body_a];
    SolverBody& second_b = bodies_[rows_[second_row].body_b];
    RunVelocities first = LoadRun<kPseudo>(first_a, first_b);
    RunVelocities second = LoadRun<kPseudo>(second_a, second_b);
    double first_change_squared = 0.0;
    double second_change_squared = 0.0;
    std::uint32_t r = first_begin;
    std::uint32_t s = second_begin;
    while (r < first_end || s < second_end) {
      if (r < first_end) {
        first_change_squared = std::max(
            first_change_squared, UpdateRow<kPseudo>(correction, inverse_dt, &rows_[r++], &first));
      }
      if (s < second_end) {
        second_change_squared =
            std::max(second_change_squared,
                     UpdateRow<kPseudo>(correction, inverse_dt, &rows_[s++], &second));
      }
    }
    if (paired) StoreRun<kPseudo>(second, &second_a, &second_b);
    StoreRun<kPseudo>(first, &first_a, &first_b);
    if constexpr (!kPseudo) {
      double& first_largest = islands_[first_island].largest_change_squared;
      first_largest = std::max(first_largest, first_change_squared);
      if (paired) {
        double& second_largest = islands_[task.second_island].largest_change_squared;
        second_largest = std::max(second_largest, second_change_squared);
      }
    }
  }
}

// Gauss-Seidel updates of rows that share no body the solve can move commute
// exactly, in floating point too: each reads and writes only its own
// bodies' velocities. So a run of rows (one body pair's) may move forward
// past runs it shares no moving body with, to be updated side by side with
// the run it then follows. A sweep in this order gives bit for bit the
// sweep in manifold order, while the processor overlaps two independent
// chains of updates, where one chain leaves it waiting on each update's
// result (a third chain measured no faster). Greedy, in manifold order: each
// run not yet scheduled takes the first of the next kPartnerWindow such runs
// that shares no moving body with it nor with the runs it would pass.
void ContactSolver::ScheduleRuns() {
  struct Run {
    std::uint32_t begin;
    std::uint32_t end;
    std::array<std::uint32_t, 2> moving;  // kFixedBody for a body that does not move
    bool scheduled;
  };
  auto moving = [&](std::uint32_t index) { return Moves(bodies_[index]) ? index : kFixedBody; };
  std::vector<Run> runs;
  for (std::uint32_t r = 0; r < rows_.size();) {
    const std::uint32_t begin = r;
    const std::uint32_t a = rows_[r].body_a;
    const std::uint32_t b = rows_[r].body_b;
    while (r < rows_.size() && rows_[r].body_a == a && rows_[r].body_b == b) ++r;
    runs.push_back({begin, r, {moving(a), moving(b)}, false});
  }
  schedule_.clear();
  std::vector<std::uint32_t> blocked;
  auto is_blocked = [&](const Run& run) {
    for (const std::uint32_t body : run.moving) {
      if (body != kFixedBody && std::find(blocked.begin(), blocked.end(), body) != blocked.end()) {
        return true;
      }
    }
    return false;
  };
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (runs[i].scheduled) continue;
    runs[i].scheduled = true;
    SweepTask& task = schedule_.emplace_back();
    task.first_begin = runs[i].begin;
    task.first_end = runs[i].end;
    task.second_begin = task.second_end = runs[i].end;
    task.first_island = task.second_island = row_island_[runs[i].begin];
    blocked.assign(runs[i].moving.begin(), runs[i].moving.end());
    const int window = settings_.interleave_independent_runs ? kPartnerWindow : 0;
    int looked = 0;
    for (std::size_t j = i + 1; j < runs.size() && looked < window; ++j) {
      if (runs[j].scheduled) continue;
      ++looked;
      if (!is_blocked(runs[j])) {
        runs[j].scheduled = true;
        task.second_begin = runs[j].begin;
        task.second_end = runs[j].end;
        task.second_island = row_island_[runs[j].begin];
        break;
      }
      blocked.insert(blocked.end(), runs[j].moving.begin(), runs[j].moving.end());
    }
  }
}

// Rows of different islands share no body the solve moves, so a sweep's
// updates of one island never read another's results, and an island can
// stop sweeping once it alone has converged: a quiet island stops early
// while a busy one goes on, and each island's rows are updated in the same
// order as if it were alone in the world. Islands by union-find over the
// rows' moving bodies, numbered in the order of their first row.
void ContactSolver::FindIslands() {
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  island_sets_.Reset(bodies_.size());
  for (const RestingRow& row : rows_) {
    if (Moves(bodies_[row.body_a]) && Moves(bodies_[row.body_b])) {
      island_sets_.Join(row.body_a, row.body_b);
    }
  }
  island_of_root_.assign(bodies_.size(), kNone);
  row_island_.resize(rows_.size());
  islands_.clear();
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    // A row between two bodies that do not move changes nothing; it takes
    // body B's set, which no row joins, so it is an island of its own rows.
    const std::uint32_t body = Moves(bodies_[rows_[r].body_a]) ? rows_[r].body_a : rows_[r].body_b;
    std::uint32_t& island = island_of_root_[island_sets_.Find(body)];
    if (island == kNone) {
      island = static_cast<std::uint32_t>(islands_.size());
      islands_.emplace_back();
    }
    row_island_[r] = island;
    ++islands_[island].row_count;
  }
}

namespace {

// v_r of a row from the solver's bodies: v_a + w_a x r_a - v_b - w_b x r_b.
Vec3 RowVelocity(const RestingRow& row, const std::vector<SolverBody>& bodies) {
  const SolverBody& a = bodies[row.body_a];
  const SolverBody& b = bodies[row.body_b];
  return a.linear_velocity + a.angular_velocity.cross(row.r_a) - b.linear_velocity -
         b.angular_velocity.cross(row.r_b);
}

void ApplyRowImpulse(const RestingRow& row, const Vec3& components,
                     std::vector<SolverBody>* bodies) {
  SolverBody& a = (*bodies)[row.body_a];
  SolverBody& b = (*bodies)[row.body_b];
  RunVelocities velocities = LoadRun</*kPseudo=*/false>(a, b);
  AddRowImpulse(row, components, &velocities);
  StoreRun</*kPseudo=*/false>(velocities, &a, &b);
}

// n_i . (change of v_r at row i per unit normal impulse at row k): A_ik of
// the resting LCP, J_i M^-1 J_k^T, from row k's responses I^-1 (r x n).
double NormalResponse(const RestingRow& row_i, const RestingRow& row_k) {
  Vec3 relative = Vec3::Zero();
  auto add = [&](std::uint32_t body, const Vec3& r, double sign) {
    if (body == row_k.body_a) {
      relative += sign * (row_k.inverse_mass_a * row_k.normal + row_k.angular_a[0].cross(r));
    }
    if (body == row_k.body_b) {
      relative -= sign * (row_k.inverse_mass_b * row_k.normal + row_k.angular_b[0].cross(r));
    }
  };
  add(row_i.body_a, row_i.r_a, 1.0);
  add(row_i.body_b, row_i.r_b, -1.0);
  return row_i.normal.dot(relative);
}

}  // namespace

// An island the sweeps left unconverged, with at most max_pivoting_points
// rows, has its normal impulses solved again by pivoting (lcp.h), all at
// once and exactly, with its friction impulses held: f >= 0,
// w = A f + b >= 0, f . w = 0, where w_i = n_i . v_r,i - target_i and
// A_ik = J_i M^-1 J_k^T (Baraff, seed 002, "Resting Contact"), so
// b = w(now) - A f(now). Gauss-Seidel gains about m/M of the way per sweep
// where a light body carries a heavy one; pivoting does not depend on the
// masses. Friction that the new normal impulses leave outside its cone is
// projected back onto it.
bool ContactSolver::FinishIslandsExactly() {
  // The rows of the islands to finish, grouped by island (a counting sort):
  // island i's are exact_rows_[exact_begin_[i], exact_begin_[i + 1]).
  auto finishes = [&](const RestingIsland& island) {
    return !island.converged && static_cast<int>(island.row_count) <= settings_.max_pivoting_points;
  };
  if (std::none_of(islands_.begin(), islands_.end(), finishes)) return false;
  exact_begin_.assign(islands_.size() + 1, 0);
  for (std::uint32_t island = 0; island < islands_.size(); ++island) {
    const std::uint32_t count = finishes(islands_[island]) ? islands_[island].row_count : 0;
    exact_begin_[island + 1] = exact_begin_[island] + count;
  }
  exact_rows_.resize(exact_begin_.back());
  std::vector<std::uint32_t> next(exact_begin_.begin(), exact_begin_.end() - 1);
  for (std::uint32_t r = 0; r < rows_.size(); ++r) {
    const std::uint32_t island = row_island_[r];
    if (finishes(islands_[island])) exact_rows_[next[island]++] = r;
  }
  for (std::uint32_t island = 0; island < islands_.size(); ++island) {
    const int n = static_cast<int>(exact_begin_[island + 1] - exact_begin_[island]);
    if (n == 0) continue;
    const std::uint32_t* island_rows = exact_rows_.data() + exact_begin_[island];
    Eigen::MatrixXd a(n, n);
    Eigen::VectorXd b(n);
    for (int i = 0; i < n; ++i) {
      const RestingRow& row_i = rows_[island_rows[i]];
      for (int k = 0; k < n; ++k) a(i, k) = NormalResponse(row_i, rows_[island_rows[k]]);
    }
    for (int i = 0; i < n; ++i) {
      const RestingRow& row = rows_[island_rows[i]];
      b[i] = row.normal.dot(RowVelocity(row, bodies_)) - row.target;
      for (int k = 0; k < n; ++k) b[i] -= a(i, k) * rows_[island_rows[k]].normal_impulse;
    }
    const Result<LcpSolution> solution = SolveLcpLemke(a, b);
    if (!solution.ok()) continue;
    for (int k = 0; k < n; ++k) {
      RestingRow& row = rows_[island_rows[k]];
      const double change = solution->f[k] - row.normal_impulse;
      row.normal_impulse = solution->f[k];
      ApplyRowImpulse(row, Vec3(change, 0.0, 0.0), &bodies_);
    }
    for (int k = 0; k < n; ++k) {
      RestingRow& row = rows_[island_rows[k]];
      const std::array<double, 2> old_tangent = row.tangent_impulse;
      ClampToDisc(row.friction * row.normal_impulse, &row.tangent_impulse);
      const Vec3 change(0.0, row.tangent_impulse[0] - old_tangent[0],
                        row.tangent_impulse[1] - old_tangent[1]);
      if (change[1] != 0.0 || change[2] != 0.0) ApplyRowImpulse(row, change, &bodies_);
    }
  }
  // Only the finished islands sweep again.
  for (std::uint32_t island = 0; island < islands_.size(); ++island) {
    islands_[island].converged = exact_begin_[island + 1] == exact_begin_[island];
  }
  return true;
}

// Projected Gauss-Seidel, one block per point (UpdateRestingRow), in the
// schedule's order, over the islands not marked converged. An island stops
// sweeping once none of its points' relative velocities changed by more
// than velocity_tolerance since the previous sweep: its motion has
// converged, even where the impulses of redundant points (four corners where
// three would carry the load) still trade load between them.
void ContactSolver::SweepUntilConverged() {
  const double tolerance_squared = settings_.velocity_tolerance * settings_.velocity_tolerance;
  std::size_t sweeping = 0;
  for (const RestingIsland& island : islands_) sweeping += !island.converged;
  int sweeps = 0;
  while (sweeping > 0 && sweeps < settings_.velocity_iterations) {
    SweepSchedule</*kPseudo=*/false>();
    ++sweeps;
    for (RestingIsland& island : islands_) {
      if (island.converged) continue;
      velocity_row_updates_ += island.row_count;
      // The first sweep has no sweep before it to compare with.
      if (sweeps > 1 && island.largest_change_squared <= tolerance_squared) {
        island.converged = true;
        --sweeping;
      }
      island.largest_change_squared = 0.0;
    }
  }
  velocity_sweeps_ += sweeps;
}

void ContactSolver::SolveRestingContacts() {
  BuildRestingRows();
  FindIslands();
  ScheduleRuns();
  for (const RestingRow& row : rows_) {
    ApplyRowImpulse(row, Vec3(row.normal_impulse, row.tangent_impulse[0], row.tangent_impulse[1]),
                    &bodies_);
  }

  velocity_sweeps_ = 0;
  velocity_row_updates_ = 0;
  SweepUntilConverged();
  // Small islands still unconverged are solved exactly, then swept again
  // from there so that friction and the normal impulses agree.
  if (FinishIslandsExactly()) SweepUntilConverged();

  // Split impulse: pseudo velocities remove penetration beyond the slop
  // without touching the real velocities, so no energy is added. The same
  // schedule, every island.
  for (int iteration = 0; iteration < settings_.position_iterations; ++iteration) {
    SweepSchedule</*kPseudo=*/true>();
  }
  for (const RestingRow& row : rows_) {
    row.point->normal_impulse = row.normal_impulse;
    row.point->tangent_impulse = row.tangent_impulse;
    row.point->pseudo_impulse = row.pseudo_impulse;
  }
}

}  // namespace rigid_body_sim::physics
