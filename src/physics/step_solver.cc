// Stage 4 of World::Step, in Baraff's order: colliding contacts get impulses
// on the velocities the step starts with; then gravity and the applied
// forces act; then resting contacts get the impulses that keep them apart.
#include <cmath>

#include "rigid_body_sim/physics/integrator.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::physics {
namespace {

// The collision log keeps at most this many points when nobody reads it.
constexpr std::size_t kMaxCollisionLogSize = 100000;

// The solver's copy of the moving bodies; the other bodies the contacts
// reach (static or asleep) get zero inverse mass and inertia. Bodies no
// contact reaches are left as they are: the solver never reads them.
void LoadVelocities(const std::vector<Body>& bodies, const std::vector<std::uint32_t>& moving,
                    const std::vector<ShapePairContact*>& pairs,
                    std::vector<SolverBody>* solver_bodies) {
  for (const ShapePairContact* pair : pairs) {
    (*solver_bodies)[pair->body_a] = SolverBody();
    (*solver_bodies)[pair->body_b] = SolverBody();
  }
  for (const std::uint32_t i : moving) {
    const Body& body = bodies[i];
    SolverBody& solver_body = (*solver_bodies)[i];
    solver_body = SolverBody();
    if (body.disabled) continue;
    solver_body.linear_velocity = body.linear_velocity;
    solver_body.angular_velocity = body.angular_velocity;
    solver_body.inverse_mass = body.inverse_mass;
    solver_body.inverse_inertia_world = body.inverse_inertia_world;
  }
}

// P = M v and L = I_world omega, with I_world = R diag(I) R^T.
void StoreVelocities(const std::vector<SolverBody>& solver_bodies,
                     const std::vector<std::uint32_t>& moving, std::vector<Body>* bodies) {
  for (const std::uint32_t i : moving) {
    Body& body = (*bodies)[i];
    if (body.disabled) continue;
    const SolverBody& solver_body = solver_bodies[i];
    body.linear_momentum = body.mass * solver_body.linear_velocity;
    const Mat3 rotation = body.orientation.toRotationMatrix();
    body.angular_momentum = rotation * body.inverse_principal_moments.cwiseInverse().asDiagonal() *
                            (rotation.transpose() * solver_body.angular_velocity);
    body.pseudo_linear_velocity = solver_body.pseudo_linear_velocity;
    body.pseudo_angular_velocity = solver_body.pseudo_angular_velocity;
    body.UpdateDerived();
  }
}

}  // namespace

// A resting report of point i of a pair from its cached impulses, with
// `tangent` the basis of its normal (TangentBasis) that they are in; the
// solver overwrites what it knows better for the pairs it solved.
ContactReport World::MakeReport(const ShapePairContact& pair, int i,
                                const std::array<Vec3, 2>& tangent, double dt) const {
  const ContactPoint& contact = pair.manifold.points[i];
  const CachedImpulse& impulse = pair.previous[i];
  ContactReport report;
  report.body_a = BodyId{pair.body_a, bodies_[pair.body_a].generation};
  report.body_b = BodyId{pair.body_b, bodies_[pair.body_b].generation};
  report.shape_a = pair.shape_a;
  report.shape_b = pair.shape_b;
  report.position_world = contact.position_world;
  report.normal_world = pair.manifold.normal_world;
  report.depth = std::max(0.0, -contact.separation);
  report.type = ContactType::kResting;
  report.normal_impulse = impulse.normal_impulse;
  report.friction_impulse_world =
      impulse.tangent_impulse[0] * tangent[0] + impulse.tangent_impulse[1] * tangent[1];
  report.normal_force = report.normal_impulse / dt;
  return report;
}

void World::SolveContacts(double dt) {
  // The bodies that move this step; the stages from here on visit only
  // them, so sleeping bodies cost nothing.
  moving_bodies_.clear();
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    const Body& body = bodies_[i];
    if (body.in_use && !body.is_static && body.awake && !body.disabled) moving_bodies_.push_back(i);
  }
  solver_.Reset(settings_.solver, dt, bodies_.size());
  const std::vector<ShapePairContact*>& pairs = contact_cache_.touching();
  LoadVelocities(bodies_, moving_bodies_, pairs, &solver_.bodies());
  std::vector<SolverManifold>& manifolds = solver_.manifolds();
  manifolds.reserve(pairs.size());
  for (const ShapePairContact* pair : pairs) {
    const Body& a = bodies_[pair->body_a];
    const Body& b = bodies_[pair->body_b];
    // Built in place: a manifold with its four points is 648 bytes.
    SolverManifold& manifold = manifolds.emplace_back();
    manifold.body_a = pair->body_a;
    manifold.body_b = pair->body_b;
    manifold.normal_world = pair->manifold.normal_world;
    const Material& material_a = a.shapes[pair->shape_a].material;
    const Material& material_b = b.shapes[pair->shape_b].material;
    manifold.friction = CombineFriction(material_a.friction, material_b.friction);
    manifold.restitution = CombineRestitution(material_a.restitution, material_b.restitution);
    manifold.point_count = pair->manifold.point_count;
    for (int i = 0; i < manifold.point_count; ++i) {
      const ContactPoint& contact = pair->manifold.points[i];
      SolverPoint& point = manifold.points[i];
      point.r_a = contact.position_world - a.position;
      point.r_b = contact.position_world - b.position;
      point.separation = contact.separation;
      point.feature = contact.feature;
      point.normal_impulse = pair->warm_start[i].normal_impulse;
      point.tangent_impulse = pair->warm_start[i].tangent_impulse;
    }
  }
  solver_.Prepare();

  solver_.ResolveCollisions();
  solver_.RecordStartVelocities();
  StoreVelocities(solver_.bodies(), moving_bodies_, &bodies_);
  IntegrateForces(settings_.gravity, dt, moving_bodies_, &bodies_);
  DisableNonFiniteBodies();
  LoadVelocities(bodies_, moving_bodies_, pairs, &solver_.bodies());
  solver_.SolveRestingContacts();
  StoreVelocities(solver_.bodies(), moving_bodies_, &bodies_);
  // A body that resting contact pushed this step drifts with its end
  // velocity (symplectic Euler), which keeps the momentum exchanged through
  // contacts exactly conserved; the free ones keep the trapezoid's exact
  // parabola (integrator.h).
  for (const SolverManifold& manifold : manifolds) {
    for (int i = 0; i < manifold.point_count; ++i) {
      if (manifold.points[i].normal_impulse <= 0.0) continue;
      for (const std::uint32_t index : {manifold.body_a, manifold.body_b}) {
        bodies_[index].start_linear_velocity = bodies_[index].linear_velocity;
      }
    }
  }

  // Sleeping bodies keep the contacts they fell asleep with; their reports
  // are made again only when the list of sleeping pairs changes.
  if (sleeping_reports_version_ != contact_cache_.sleeping_version()) {
    contacts_.clear();
    for (const ShapePairContact* pair : contact_cache_.sleeping()) {
      const std::array<Vec3, 2> tangent = TangentBasis(pair->manifold.normal_world);
      for (int i = 0; i < pair->manifold.point_count; ++i) {
        if (pair->manifold.points[i].separation > settings_.solver.contact_tolerance) continue;
        contacts_.push_back(MakeReport(*pair, i, tangent, dt));
      }
    }
    sleeping_reports_version_ = contact_cache_.sleeping_version();
    sleeping_report_count_ = contacts_.size();
  }
  contacts_.resize(sleeping_report_count_);

  // Keep the impulses for next step's warm start, and report the points
  // that touch.
  for (std::size_t m = 0; m < manifolds.size(); ++m) {
    const SolverManifold& manifold = manifolds[m];
    ShapePairContact& pair = *pairs[m];
    pair.previous_count = manifold.point_count;
    for (int i = 0; i < manifold.point_count; ++i) {
      const SolverPoint& point = manifold.points[i];
      pair.previous[i] = CachedImpulse{point.feature, point.normal_impulse, point.tangent_impulse,
                                       pair.manifold.points[i].position_world};
      const bool touching = point.separation <= settings_.solver.contact_tolerance;
      if (!touching && point.type != ContactType::kColliding) continue;
      ContactReport& report =
          contacts_.emplace_back(MakeReport(pair, i, manifold.tangent_world, dt));
      report.normal_velocity = point.normal_velocity_before;
      report.type = point.type;
      report.normal_impulse = point.collision_impulse + point.normal_impulse;
      report.normal_force = report.normal_impulse / dt;
      if (report.type == ContactType::kColliding) collision_log_.push_back(report);
    }
  }
  if (collision_log_.size() > kMaxCollisionLogSize) {
    collision_log_.erase(collision_log_.begin(),
                         collision_log_.end() - static_cast<std::ptrdiff_t>(kMaxCollisionLogSize));
  }
}

}  // namespace rigid_body_sim::physics
