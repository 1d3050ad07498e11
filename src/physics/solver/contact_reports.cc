// The step's contact reports (contact_reports.h): kept impulses, counted
// and placed reports, written at once for the collisions and when first
// read for the rest.
#include "physics/solver/contact_reports.h"

#include <algorithm>

#include "physics/collision/mesh_collision.h"
#include "physics/contact/contact_frame.h"

namespace rigid_body_sim::physics {
namespace {

// When nobody reads the collision log, it keeps the newest this many points
// at least and twice this many at most: trimmed to this size only once it
// has doubled, so the trimming's copy costs a constant per point logged.
// Trimmed at every step past the bound, a pile whose settling points count
// as colliding copied the whole log each step (8 % of a soft step on 1,000
// boxes).
constexpr std::size_t kMaxCollisionLogSize = 100000;

// Manifolds a thread takes at a time when the contacts are reported on the
// pool.
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

ContactReports::ContactReports(const ContactReportsWorld& world)
    : bodies_(*world.bodies),
      solver_(*world.solver),
      contact_cache_(*world.contact_cache),
      settings_(*world.settings) {}

// A resting report of point i of a pair from its cached impulses, with
// `tangent` the basis of its normal (TangentBasis) that they are in; the
// solver overwrites what it knows better for the pairs it solved.
ContactReport ContactReports::MakeReport(const ShapePairContact& pair, int i,
                                         const std::array<Vec3, 2>& tangent,
                                         const StepContext& step) const {
  ContactReport report;
  PairReporter(pair, tangent, bodies_, step.dt).Write(i, &report);
  return report;
}

// Keeps the impulses for next step's warm start, and places the points that
// touch after the sleeping pairs' reports. Only the colliding ones are
// written now, for the collision log; the others are written when they are
// first read (Flush): most steps of a node that publishes at a tenth
// of its step rate are never read, and writing a report costs about what
// the solve of its point does (a 4,095-box pyramid: 10 % of the soft step).
void ContactReports::ReportSolved(const std::vector<ShapePairContact*>& pairs,
                                  const StepContext& step, bool impacts_only) {
  // A sub-step's manifolds replace the step's: its reports were written
  // before (ExactSolver::ResolveImpacts).
  assert(!(impacts_only && pending_.pending));
  const std::vector<SolverManifold>& manifolds = solver_.manifolds();
  const std::size_t first_report = impacts_only ? contacts_.size() : ReportSleeping(step);
  const double contact_tolerance = settings_.solver.contact_tolerance;
  // On the pool: each pair keeps its points for the next step's warm start,
  // and counts its reports; their offsets in contacts_ follow, in manifold
  // order; then the pairs with a collision write their reports.
  const std::size_t count = manifolds.size();
  offsets_.resize(count + 1);
  collided_.resize(count);
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
    offsets_[m + 1] = reports;
    collided_[m] = collided ? 1 : 0;
  });
  offsets_[0] = static_cast<std::uint32_t>(first_report);
  bool any_collided = false;
  for (std::size_t m = 0; m < count; ++m) {
    offsets_[m + 1] += offsets_[m];
    any_collided |= collided_[m] != 0;
  }
  // One resize to the new length: the last step's reports past the sleeping
  // ones are overwritten, not constructed afresh first (constructing a
  // report costs about what writing it does).
  contacts_.resize(offsets_[count]);
  // Most steps of a settled scene have no collision.
  if (any_collided) {
    step.pool->ParallelFor(count, kManifoldsPerChunk, [&](std::size_t m) {
      if (collided_[m]) Write(m, pairs, step.dt, impacts_only);
    });
    for (std::size_t m = 0; m < count; ++m) {
      if (!collided_[m]) continue;
      for (std::uint32_t k = offsets_[m]; k < offsets_[m + 1]; ++k) {
        if (contacts_[k].type == ContactType::kColliding) collision_log_.push_back(contacts_[k]);
      }
    }
  }
  if (collision_log_.size() > 2 * kMaxCollisionLogSize) {
    collision_log_.erase(collision_log_.begin(),
                         collision_log_.end() - static_cast<std::ptrdiff_t>(kMaxCollisionLogSize));
  }
  pending_ = Pending{&pairs, step.dt, impacts_only, true};
  // A sub-step's reports are written at once: the sub-step after it builds
  // its manifolds afresh.
  if (impacts_only) Flush(step.pool);
}

// Manifold m's reports at its offset; each report is a function of the
// manifold, its pair and the bodies' slots alone, so writing one twice
// writes the same.
void ContactReports::Write(std::size_t m, const std::vector<ShapePairContact*>& pairs, double dt,
                           bool impacts_only) {
  const SolverManifold& manifold = solver_.manifolds()[m];
  const ShapePairContact& pair = *pairs[m];
  const double contact_tolerance = settings_.solver.contact_tolerance;
  std::uint32_t next = offsets_[m];
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

// Writes the last ReportSolved's reports that are not written yet, on the
// pool. Called before anything reads contacts_ and before anything changes
// what the reports are made of (the pairs, the solver manifolds, the
// bodies' slots).
void ContactReports::Flush(TaskPool* pool) {
  if (!pending_.pending) return;
  pending_.pending = false;
  const Pending pending = pending_;
  pool->ParallelFor(collided_.size(), kManifoldsPerChunk, [&](std::size_t m) {
    PrefetchAhead(*pending.pairs, m, PrefetchPoints);
    if (!collided_[m]) Write(m, *pending.pairs, pending.dt, pending.impacts_only);
  });
}

// Sleeping bodies keep the contacts they fell asleep with; their reports are
// made again only when the list of sleeping pairs changes, and the reports
// of this step follow them. Returns their count: contacts_ keeps its length
// until ReportSolved resizes it.
std::size_t ContactReports::ReportSleeping(const StepContext& step) {
  if (sleeping_version_ != contact_cache_.sleeping_version()) {
    contacts_.clear();
    for (const ShapePairContact* pair : contact_cache_.sleeping()) {
      const std::array<Vec3, 2> tangent = TangentBasis(pair->manifold.normal_world);
      for (int i = 0; i < pair->manifold.point_count; ++i) {
        if (pair->manifold.points[i].separation > settings_.solver.contact_tolerance) continue;
        contacts_.push_back(MakeReport(*pair, i, tangent, step));
      }
    }
    sleeping_version_ = contact_cache_.sleeping_version();
    sleeping_count_ = contacts_.size();
  }
  return sleeping_count_;
}

void ContactReports::Append(const ContactReport& report) {
  contacts_.push_back(report);
  if (report.type == ContactType::kColliding) collision_log_.push_back(report);
}

void ContactReports::ForgetBody(std::uint32_t index, TaskPool* pool) {
  Flush(pool);
  const auto touches = [index](const ContactReport& contact) {
    return contact.body_a.index == index || contact.body_b.index == index;
  };
  contacts_.erase(std::remove_if(contacts_.begin(), contacts_.end(), touches), contacts_.end());
  collision_log_.erase(std::remove_if(collision_log_.begin(), collision_log_.end(), touches),
                       collision_log_.end());
  // The sleeping pairs' reports at the front of contacts_ are made afresh.
  sleeping_version_ = ~std::uint64_t{0};
  sleeping_count_ = 0;
}

void ContactReports::Clear() {
  pending_.pending = false;
  contacts_.clear();
  collision_log_.clear();
}

std::vector<ContactReport> ContactReports::TakeCollisionLog() {
  std::vector<ContactReport> log;
  log.swap(collision_log_);
  return log;
}

}  // namespace rigid_body_sim::physics
