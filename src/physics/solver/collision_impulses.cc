// Colliding contact: rounds of simultaneous impulses with restitution.
#include "physics/solver/contact_solver.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>

#include "physics/solver/lcp.h"
#include "physics/solver/resting_row.h"

namespace rigid_body_sim::physics {
namespace {

// Sweeps of a collision round stop once no impulse changes by more than this
// fraction of the largest impulse.
constexpr double kCollisionConvergence = 1e-10;

// 1 / (1/Ma + 1/Mb + (ra x d).Ia^-1 (ra x d) + (rb x d).Ib^-1 (rb x d)):
// the mass the contact "feels" along d (Baraff 1997, "Rigid Body
// Simulation II", section 8, the denominator of eq. (8-18)).
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

// 1/2 m |v|^2 + 1/2 w . I w of the given solver bodies, J; I w from the
// world inverse inertia. Bodies that do not move (zero inverse mass) have
// none.
double KineticEnergy(const std::vector<SolverBody>& bodies,
                     const std::vector<std::uint32_t>& indices) {
  double energy = 0.0;
  for (const std::uint32_t index : indices) {
    const SolverBody& body = bodies[index];
    if (body.inverse_mass == 0.0) continue;
    energy += 0.5 * body.linear_velocity.squaredNorm() / body.inverse_mass;
    const Eigen::LDLT<Mat3> inverse_inertia(body.inverse_inertia_world);
    energy += 0.5 * body.angular_velocity.dot(inverse_inertia.solve(body.angular_velocity));
  }
  return energy;
}

}  // namespace

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
        if (ClassifyContactPoint(point.separation, v_r, settings_) == ContactType::kColliding)
          active.emplace_back(m, i);
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
    collision_bodies_.clear();
    for (const auto& [m, i] : active) {
      collision_bodies_.push_back(manifolds_[m].body_a);
      collision_bodies_.push_back(manifolds_[m].body_b);
    }
    std::sort(collision_bodies_.begin(), collision_bodies_.end());
    collision_bodies_.erase(std::unique(collision_bodies_.begin(), collision_bodies_.end()),
                            collision_bodies_.end());
    const double energy_before = KineticEnergy(bodies_, collision_bodies_);
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
    const double scale = ApplyRestitution(active, normal, last_round, energy_before);
    for (std::size_t k = 0; k < active.size(); ++k) {
      SolverManifold& manifold = manifolds_[active[k].first];
      SolverPoint& point = manifold.points[active[k].second];
      const double restitution = last_round ? 0.0 : scale * manifold.restitution;
      point.collision_impulse += (1.0 + restitution) * normal[k];
      point.type = ContactType::kColliding;
    }
  }
}

// Poisson's hypothesis adds e j_c along the normal after the compression
// impulses j_c. Without friction that never adds energy, dE = -(1 - e^2)/2
// j_c.A j_c; with friction it can, for an eccentric impact whose friction
// in compression took less energy than the restitution gives back (Stronge
// 1991, "Unraveling paradoxical theories for rigid body collisions", J.
// Appl. Mech. 58(4), for slip that halts or reverses; Glocker 2013,
// "Energetic consistency conditions for standard impacts, Part II",
// Multibody Syst. Dyn. 32, for Poisson's law at several frictional
// contacts). A body of 1 kg with I = 0.05 kg m^2 striking 1 m from its
// centre with e = 1 and mu = 0.5 left with four times the energy it came
// with. So a round applies only as much of its restitution impulses,
// s e j_c with s in [0, 1], as leaves the kinetic energy of its bodies at
// most what it was before the compression: applying s R to velocities u
// changes the energy by b s + q s^2, b = sum_k R_k . u_k (zero where the
// compression left v_r = 0) and q = 1/2 R.A R, measured by applying R once.
// Returns s.
double ContactSolver::ApplyRestitution(const std::vector<std::pair<int, int>>& active,
                                       const std::vector<double>& normal, bool last_round,
                                       double energy_before) {
  if (last_round) return 0.0;
  const double energy_compressed = KineticEnergy(bodies_, collision_bodies_);
  double b = 0.0;
  for (std::size_t k = 0; k < active.size(); ++k) {
    const SolverManifold& manifold = manifolds_[active[k].first];
    const SolverPoint& point = manifold.points[active[k].second];
    b += manifold.restitution * normal[k] * NormalVelocity(manifold, point);
  }
  auto apply = [&](double fraction) {
    for (std::size_t k = 0; k < active.size(); ++k) {
      const SolverManifold& manifold = manifolds_[active[k].first];
      const SolverPoint& point = manifold.points[active[k].second];
      ApplyImpulse(manifold, point,
                   fraction * manifold.restitution * normal[k] * manifold.normal_world);
    }
  };
  apply(1.0);
  const double energy_restituted = KineticEnergy(bodies_, collision_bodies_);
  if (energy_restituted <= energy_before) return 1.0;
  const double q = energy_restituted - energy_compressed - b;
  const double scale = RestitutionScale(b, q, energy_before - energy_compressed);
  apply(scale - 1.0);
  return scale;
}

}  // namespace rigid_body_sim::physics
