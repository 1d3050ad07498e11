// Stage 4 of WorldImpl::Step, in Baraff's order: colliding contacts get impulses
// on the velocities the step starts with; then gravity and the applied
// forces act; then resting contacts get the impulses that keep them apart.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "physics/collision/mesh_collision.h"
#include "physics/dynamics/integrator.h"
#include "physics/solver/support_balance.h"
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {
namespace {

// When nobody reads the collision log, it keeps the newest this many points
// at least and twice this many at most: trimmed to this size only once it
// has doubled, so the trimming's copy costs a constant per point logged.
// Trimmed at every step past the bound, a pile whose settling points count
// as colliding copied the whole log each step (8 % of a soft step on 1,000
// boxes).
constexpr std::size_t kMaxCollisionLogSize = 100000;

// Manifolds a thread takes at a time when the solver manifolds are built
// and the contacts reported on the pool.
constexpr std::size_t kManifoldsPerChunk = 256;

// Writes the reports of one pair's points. What they share (the bodies with
// their generations, and the caller's shapes, which a static mesh's slot
// copies map back) is looked up once a pair instead of once a point.
class PairReporter {
 public:
  // `tangent` is the basis of the pair's normal (TangentBasis) that its
  // cached impulses are in.
  PairReporter(const ShapePairContact& pair, const std::array<Vec3, 2>& tangent,
               const std::vector<Body>& bodies, double dt)
      : pair_(pair),
        tangent_(tangent),
        body_a_{pair.body_a, bodies[pair.body_a].generation},
        body_b_{pair.body_b, bodies[pair.body_b].generation},
        shape_a_(CallerShape(bodies[pair.body_a].shapes, pair.shape_a)),
        shape_b_(CallerShape(bodies[pair.body_b].shapes, pair.shape_b)),
        dt_(dt) {}

  // Every field of point i's report, as a resting contact with the pair's
  // cached impulses.
  void Write(int i, ContactReport* report) const {
    const ContactPoint& contact = pair_.manifold.points[i];
    const CachedImpulse& impulse = pair_.previous[i];
    report->body_a = body_a_;
    report->body_b = body_b_;
    report->shape_a = shape_a_;
    report->shape_b = shape_b_;
    report->position_world = contact.position_world;
    report->normal_world = pair_.manifold.normal_world;
    report->depth = std::max(0.0, -contact.separation);
    report->normal_velocity = 0.0;
    report->type = ContactType::kResting;
    report->normal_impulse = impulse.normal_impulse;
    report->friction_impulse_world =
        impulse.tangent_impulse[0] * tangent_[0] + impulse.tangent_impulse[1] * tangent_[1];
    report->normal_force = report->normal_impulse / dt_;
  }

 private:
  const ShapePairContact& pair_;
  const std::array<Vec3, 2>& tangent_;
  BodyId body_a_;
  BodyId body_b_;
  int shape_a_;
  int shape_b_;
  double dt_;  // s
};

}  // namespace

// A resting report of point i of a pair from its cached impulses, with
// `tangent` the basis of its normal (TangentBasis) that they are in; the
// solver overwrites what it knows better for the pairs it solved.
ContactReport WorldImpl::MakeReport(const ShapePairContact& pair, int i,
                                    const std::array<Vec3, 2>& tangent,
                                    const StepContext& step) const {
  ContactReport report;
  PairReporter(pair, tangent, bodies_, step.dt).Write(i, &report);
  return report;
}

// A support that is new this step (a pair that had no contact point last
// step, and touches at every point now) starts the resting solve from the
// load it would carry at rest, instead of from zero. Statics of a stack,
// from the highest body down: a body's load is its weight m g dt plus the
// loads resting on it; the part its warm supports do not carry already
// (their impulses n / (n.up)) is shared equally by its new supports, whose
// points take the normal part n.up of their share; each support passes its
// load to the body below. Without it, Gauss-Seidel sweeps from zero move a
// load up a stack by about one level per sweep, so a stack spawned at rest
// sags and rocks for its first tenth of a second. The estimate is only
// where the iteration starts: the complementarity conditions, and so the
// solution, are the same. Returns the upright supports it walked (none when
// no support is new), for the soft step's spread.
std::vector<UprightSupport> WorldImpl::SeedNewSupportLoads(const StepContext& step) {
  const double g = settings_.gravity.norm();
  if (g <= 0.0) return {};
  std::vector<SolverManifold>& manifolds = solver_.manifolds();
  std::vector<UprightSupport> supports = UprightSupportsHighestFirst(SupportInput(step), manifolds);
  if (supports.empty()) return supports;
  // N s: a body's load; then, from its first support on, what its new
  // supports share.
  std::vector<double> load(bodies_.size(), 0.0);
  std::vector<int> new_supports(bodies_.size(), 0);
  for (const UprightSupport& support : supports) {
    load[support.upper] = bodies_[support.upper].mass * g * step.dt;
    if (support.is_new) ++new_supports[support.upper];
  }
  auto warm_load = [&](const UprightSupport& support) {
    const SolverManifold& manifold = manifolds[support.manifold];
    double normal = 0.0;
    for (int i = 0; i < manifold.point_count; ++i) normal += manifold.points[i].normal_impulse;
    return normal / support.up_along_normal;
  };
  for (std::size_t k = 0; k < supports.size(); ++k) {
    const std::uint32_t upper = supports[k].upper;
    if (k == 0 || supports[k - 1].upper != upper) {
      for (std::size_t w = k; w < supports.size() && supports[w].upper == upper; ++w) {
        if (!supports[w].is_new) load[upper] -= warm_load(supports[w]);
      }
      load[upper] = std::max(load[upper], 0.0);
    }
    const UprightSupport& support = supports[k];
    double passed = 0.0;
    if (!support.is_new) {
      passed = warm_load(support);
    } else if (CarriesLoad(bodies_[upper])) {
      passed = load[upper] / new_supports[upper];
      SolverManifold& manifold = manifolds[support.manifold];
      const double per_point = passed * support.up_along_normal / manifold.point_count;
      for (int i = 0; i < manifold.point_count; ++i) manifold.points[i].normal_impulse = per_point;
    }
    if (CarriesLoad(bodies_[support.lower])) load[support.lower] += passed;
  }
  return supports;
}

SupportBalanceInput WorldImpl::SupportInput(const StepContext& step) const {
  SupportBalanceInput input;
  input.bodies = &bodies_;
  input.gravity = settings_.gravity;
  input.dt = step.dt;
  input.contact_tolerance = settings_.solver.contact_tolerance;
  return input;
}

// The bodies that move this step; the stages from here on visit only them,
// so sleeping bodies cost nothing.
void WorldImpl::ListMovingBodies() {
  moving_bodies_.clear();
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    if (MovesThisStep(bodies_[i])) moving_bodies_.push_back(i);
  }
}

// One solver manifold per touching pair, with its points' lever arms,
// combined materials and last step's impulses.
void WorldImpl::BuildSolverManifolds(const std::vector<ShapePairContact*>& pairs,
                                     const StepContext& step) {
  std::vector<SolverManifold>& manifolds = solver_.manifolds();
  // Resized, not cleared (ContactSolver::Reset keeps them): a manifold with
  // its four points is 648 bytes, and each is built afresh below, on the pool.
  manifolds.resize(pairs.size());
  std::vector<std::array<std::uint32_t, 2>>& manifold_bodies = solver_.manifold_bodies();
  manifold_bodies.resize(pairs.size());
  step.pool->ParallelFor(pairs.size(), kManifoldsPerChunk, [&](std::size_t m) {
    PrefetchAhead(pairs, m, PrefetchPoints);
    const ShapePairContact* pair = pairs[m];
    manifold_bodies[m] = {pair->body_a, pair->body_b};
    const Body& a = bodies_[pair->body_a];
    const Body& b = bodies_[pair->body_b];
    // Reset field by field: assigning a fresh SolverManifold built all four
    // points (648 bytes) and copied them. Points past point_count keep an
    // earlier step's values; nothing reads them.
    SolverManifold& manifold = manifolds[m];
    manifold.tangent_world = {Vec3::UnitX(), Vec3::UnitY()};  // as constructed
    manifold.body_a = pair->body_a;
    manifold.body_b = pair->body_b;
    manifold.normal_world = pair->manifold.normal_world;
    const Material& material_a = a.shapes[pair->shape_a].material;
    const Material& material_b = b.shapes[pair->shape_b].material;
    manifold.friction = CombineFriction(material_a.friction, material_b.friction);
    manifold.restitution = CombineRestitution(material_a.restitution, material_b.restitution);
    manifold.point_count = pair->manifold.point_count;
    manifold.new_pair = pair->previous_count == 0;
    for (int i = 0; i < manifold.point_count; ++i) {
      const ContactPoint& contact = pair->manifold.points[i];
      SolverPoint& point = manifold.points[i];
      point = SolverPoint();
      point.r_a = contact.position_world - a.position;
      point.r_b = contact.position_world - b.position;
      point.separation = contact.separation;
      point.feature = contact.feature;
      const CachedImpulse& warm = pair->WarmStart(i);
      point.normal_impulse = warm.normal_impulse;
      point.tangent_impulse = warm.tangent_impulse;
      point.preload = warm.preload;
      point.carried_approach = warm.approach_velocity;
    }
  });
}

namespace {

// Whether a solved point is reported. A collision is reported only where an
// impulse resolved it; a sub-step after an impact reports only its
// collisions, the step's own report holding the resting contacts.
bool IsReported(const SolverPoint& point, double contact_tolerance, bool impacts_only) {
  const bool touching = point.separation <= contact_tolerance;
  const bool collided =
      point.type == ContactType::kColliding && point.collision_impulse + point.normal_impulse > 0.0;
  const bool shown = point.type == ContactType::kColliding ? collided : touching;
  return shown && (!impacts_only || collided);
}

}  // namespace

// Keeps the impulses for next step's warm start, and places the points that
// touch after the sleeping pairs' reports. Only the colliding ones are
// written now, for the collision log; the others are written when they are
// first read (FlushReports): most steps of a node that publishes at a tenth
// of its step rate are never read, and writing a report costs about what
// the solve of its point does (a 4,095-box pyramid: 10 % of the soft step).
void WorldImpl::ReportContacts(const std::vector<ShapePairContact*>& pairs, const StepContext& step,
                               bool impacts_only) {
  // A sub-step's manifolds replace the step's: its reports were written
  // before (ExactSolver::ResolveImpacts).
  assert(!(impacts_only && pending_reports_.pending));
  const std::vector<SolverManifold>& manifolds = solver_.manifolds();
  const std::size_t first_report = impacts_only ? contacts_.size() : ReportSleepingContacts(step);
  const double contact_tolerance = settings_.solver.contact_tolerance;
  // On the pool: each pair keeps its points for the next step's warm start,
  // and counts its reports; their offsets in contacts_ follow, in manifold
  // order; then the pairs with a collision write their reports.
  const std::size_t count = manifolds.size();
  report_offsets_.resize(count + 1);
  report_collided_.resize(count);
  step.pool->ParallelFor(count, kManifoldsPerChunk, [&](std::size_t m) {
    PrefetchAhead(pairs, m, PrefetchPoints);
    const SolverManifold& manifold = manifolds[m];
    ShapePairContact& pair = *pairs[m];
    pair.previous_count = manifold.point_count;
    std::uint32_t reports = 0;
    bool collided = false;
    for (int i = 0; i < manifold.point_count; ++i) {
      const SolverPoint& point = manifold.points[i];
      pair.previous[i] =
          CachedImpulse{point.feature,         point.normal_impulse,
                        point.tangent_impulse, pair.manifold.points[i].position_world,
                        point.preload,         point.carried_approach};
      const bool reported = IsReported(point, contact_tolerance, impacts_only);
      reports += reported ? 1 : 0;
      collided |= reported && point.type == ContactType::kColliding;
    }
    report_offsets_[m + 1] = reports;
    report_collided_[m] = collided ? 1 : 0;
  });
  report_offsets_[0] = static_cast<std::uint32_t>(first_report);
  bool any_collided = false;
  for (std::size_t m = 0; m < count; ++m) {
    report_offsets_[m + 1] += report_offsets_[m];
    any_collided |= report_collided_[m] != 0;
  }
  // One resize to the new length: the last step's reports past the sleeping
  // ones are overwritten, not constructed afresh first (constructing a
  // report costs about what writing it does).
  contacts_.resize(report_offsets_[count]);
  // Most steps of a settled scene have no collision.
  if (any_collided) {
    step.pool->ParallelFor(count, kManifoldsPerChunk, [&](std::size_t m) {
      if (report_collided_[m]) WriteReports(m, pairs, step.dt, impacts_only);
    });
    for (std::size_t m = 0; m < count; ++m) {
      if (!report_collided_[m]) continue;
      for (std::uint32_t k = report_offsets_[m]; k < report_offsets_[m + 1]; ++k) {
        if (contacts_[k].type == ContactType::kColliding) collision_log_.push_back(contacts_[k]);
      }
    }
  }
  if (collision_log_.size() > 2 * kMaxCollisionLogSize) {
    collision_log_.erase(collision_log_.begin(),
                         collision_log_.end() - static_cast<std::ptrdiff_t>(kMaxCollisionLogSize));
  }
  pending_reports_ = PendingReports{&pairs, step.dt, impacts_only, true};
  // A sub-step's reports are written at once: the sub-step after it builds
  // its manifolds afresh.
  if (impacts_only) FlushReports();
}

// Manifold m's reports at its offset; each report is a function of the
// manifold, its pair and the bodies' slots alone, so writing one twice
// writes the same.
void WorldImpl::WriteReports(std::size_t m, const std::vector<ShapePairContact*>& pairs, double dt,
                             bool impacts_only) {
  const SolverManifold& manifold = solver_.manifolds()[m];
  const ShapePairContact& pair = *pairs[m];
  const double contact_tolerance = settings_.solver.contact_tolerance;
  std::uint32_t next = report_offsets_[m];
  const PairReporter reporter(pair, manifold.tangent_world, bodies_, dt);
  for (int i = 0; i < manifold.point_count; ++i) {
    const SolverPoint& point = manifold.points[i];
    if (!IsReported(point, contact_tolerance, impacts_only)) continue;
    ContactReport& report = contacts_[next++];
    reporter.Write(i, &report);
    report.normal_velocity = point.normal_velocity_before;
    report.type = point.type;
    report.normal_impulse = point.collision_impulse + point.normal_impulse;
    report.normal_force = report.normal_impulse / dt;
  }
}

// Writes the last ReportContacts' reports that are not written yet, on the
// pool. Called before anything reads contacts_ and before anything changes
// what the reports are made of (the pairs, the solver manifolds, the
// bodies' slots).
void WorldImpl::FlushReports() {
  if (!pending_reports_.pending) return;
  pending_reports_.pending = false;
  const PendingReports pending = pending_reports_;
  pool_->ParallelFor(report_collided_.size(), kManifoldsPerChunk, [&](std::size_t m) {
    PrefetchAhead(*pending.pairs, m, PrefetchPoints);
    if (!report_collided_[m]) WriteReports(m, *pending.pairs, pending.dt, pending.impacts_only);
  });
}

// Sleeping bodies keep the contacts they fell asleep with; their reports are
// made again only when the list of sleeping pairs changes, and the reports
// of this step follow them. Returns their count: contacts_ keeps its length
// until ReportContacts resizes it.
std::size_t WorldImpl::ReportSleepingContacts(const StepContext& step) {
  if (sleeping_reports_version_ != contact_cache_.sleeping_version()) {
    contacts_.clear();
    for (const ShapePairContact* pair : contact_cache_.sleeping()) {
      const std::array<Vec3, 2> tangent = TangentBasis(pair->manifold.normal_world);
      for (int i = 0; i < pair->manifold.point_count; ++i) {
        if (pair->manifold.points[i].separation > settings_.solver.contact_tolerance) continue;
        contacts_.push_back(MakeReport(*pair, i, tangent, step));
      }
    }
    sleeping_reports_version_ = contact_cache_.sleeping_version();
    sleeping_report_count_ = contacts_.size();
  }
  return sleeping_report_count_;
}

}  // namespace rigid_body_sim::physics
