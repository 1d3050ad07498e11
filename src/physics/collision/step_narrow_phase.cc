// Stage 2 of World::Step (CollisionSystem): a contact manifold for every pair of shapes of the
// candidate body pairs, each starting from its cached separating witness.
#include <algorithm>
#include <limits>
#include <variant>

#include "physics/collision/collision_system.h"
#include "physics/collision/mesh_collision.h"
#include "physics/collision/narrow_phase.h"
#include "physics/dynamics/body_frames.h"
#include "physics/geometry/shape_bounds.h"

namespace rigid_body_sim::physics {

namespace {

// Visits ahead of a pair's own at which its cache slot, then its cache
// entry, start loading: each load takes about as long as a few visits.
constexpr std::size_t kSlotPrefetchAhead = 16;
constexpr std::size_t kEntryPrefetchAhead = 8;
// A pair's contact margin is at most this fraction of its thinner body's
// thickness: with a 5 mm margin a 5 mm cube would be all within it, and the
// reduction to four points could keep its top corners and drop the bottom
// ones about to touch, which then sink into the ground unseen.
constexpr double kMarginPerThickness = 0.25;
// Shape pairs a thread takes from the narrow phase's list at a time: enough
// that taking costs nothing beside the tests (0.1-1 us each), few enough
// that a chunk of clipped pairs among carried ones evens out.
constexpr std::size_t kJobsPerChunk = 32;

// Broad-phase pairs a thread visits at a time (VisitPair): a visit loads one
// cache entry, so chunks of a few hundred keep the pool's share cheap.
constexpr std::size_t kVisitsPerChunk = 256;

// Records a shape pair's contact distance, and says whether its gap cannot
// have closed to it since the gap was found (conservative advancement's
// bound, kept across steps): such a pair is culled, with no points to match.
bool CullPair(ShapePairContact* entry, double contact_distance, double travel) {
  entry->contact_distance = contact_distance;
  if (!(entry->apart_gap - (travel - entry->apart_travel) > contact_distance)) return false;
  MatchCulled(entry);
  return true;
}

// Puts the moving body of a pair first when only one moves, so that normals
// point from the static or sleeping body B into A (CollideBodies).
void MovingBodyFirst(const std::vector<Body>& bodies, std::uint32_t* body_a,
                     std::uint32_t* body_b) {
  if (bodies[*body_a].is_static || !bodies[*body_a].awake) std::swap(*body_a, *body_b);
}

// A convex shape of body A against a static mesh shape of body B.
struct MeshVisit {
  ContactCache* cache = nullptr;
  std::uint64_t step = 0;
  const std::vector<ShapeDef>* shapes_b = nullptr;
  std::uint32_t body_a = 0;
  std::uint16_t shape_a = 0;
  std::uint32_t body_b = 0;
  int shape_b = 0;      // the mesh's own index (slot 0)
  double travel = 0.0;  // m, Body::travel of A plus B's
};

// All slots of the pair from one pass over the mesh (CollideConvexMesh):
// each group of contacts goes to its slot's cache entry. Slot 0's entry is
// always kept, and holds the gap while the shapes are apart; the others
// only while they have points.
void CollideMeshSlots(const MeshVisit& visit, const ConvexMeshPair& pair) {
  ShapePairContact& first =
      visit.cache->Touch(visit.body_a, visit.shape_a, visit.body_b,
                         static_cast<std::uint16_t>(visit.shape_b), visit.step);
  if (CullPair(&first, pair.contact_distance, visit.travel)) return;
  thread_local MeshContacts contacts;
  CollideConvexMesh(pair, &contacts);
  for (int slot = 0; slot < StaticMesh::kContactSlots; ++slot) {
    const ContactManifold& manifold = contacts.manifolds[slot];
    if (slot > 0 && manifold.point_count == 0) continue;
    const int shape = MeshSlotShape(*visit.shapes_b, visit.shape_b, slot);
    ShapePairContact& entry = visit.cache->Touch(visit.body_a, visit.shape_a, visit.body_b,
                                                 static_cast<std::uint16_t>(shape), visit.step);
    entry.contact_distance = pair.contact_distance;
    entry.manifold = manifold;
    entry.witness = SeparatingWitness{};
    entry.anchors.valid = false;
    entry.reuse_error = 0.0;
    entry.apart_gap = slot == 0 && manifold.point_count == 0
                          ? contacts.gap
                          : -std::numeric_limits<double>::infinity();
    entry.apart_travel = visit.travel;
    MatchWarmStarts(&entry);
  }
}

}  // namespace

void CollisionSystem::UpdateNarrowPhase(const StepContext& step) {
  ++step_count_;
  const std::vector<ProxyPair>& pairs = broad_phase_.Pairs();
  // The body pair in CollideBodies' order, for its first shapes' cache entry.
  auto prefetch = [&](ContactCache::Prefetch stage, std::size_t k) {
    if (k >= pairs.size()) return;
    auto a = static_cast<std::uint32_t>(pairs[k].first);
    auto b = static_cast<std::uint32_t>(pairs[k].second);
    MovingBodyFirst(bodies_, &a, &b);
    contact_cache_.PrefetchPair(stage, a, 0, b, 0);
  };
  for (std::size_t k = 0; k < std::min(pairs.size(), kSlotPrefetchAhead); ++k) {
    prefetch(ContactCache::Prefetch::kSlot, k);
  }
  // The pairs are visited on the pool, where each finds and updates its own
  // cache entry; then listed in their order, which creates the missing
  // entries and orders the visits and the jobs as a walk on one thread.
  pair_visits_.resize(pairs.size());
  step.pool->ParallelFor(pairs.size(), kVisitsPerChunk, [&](std::size_t k) {
    prefetch(ContactCache::Prefetch::kSlot, k + kSlotPrefetchAhead);
    prefetch(ContactCache::Prefetch::kEntry, k + kEntryPrefetchAhead);
    VisitPair(pairs[k], step, &pair_visits_[k]);
  });
  narrow_jobs_.clear();
  for (std::size_t k = 0; k < pairs.size(); ++k) ListPair(pairs[k], pair_visits_[k], step);
  for (const std::uint32_t plane : half_space_bodies_) VisitPlane(plane, step);
  // The listed shape pairs are tested after the walk, on the pool: a test
  // reads the bodies' poses, which no stage-2 work changes, and writes its
  // own cache entry only, so the manifolds are the same whichever thread
  // tests which pair, and the order of the entries is the walk's.
  step.pool->ParallelFor(narrow_jobs_.size(), kJobsPerChunk, [this](std::size_t j) {
    if (j + kEntryPrefetchDistance < narrow_jobs_.size()) {
      PrefetchCollide(*narrow_jobs_[j + kEntryPrefetchDistance].entry);
    }
    CollideShapePair(&narrow_jobs_[j]);
  });
  reused_manifolds_ = 0;
  for (const NarrowJob& job : narrow_jobs_) reused_manifolds_ += job.reused;
}

// The pairs of the half-space `plane` with the awake bodies near it, walked
// as the broad phase's are: each body tested and each pair visited on the
// pool, then listed here in the bodies' order.
void CollisionSystem::VisitPlane(std::uint32_t plane, const StepContext& step) {
  const Pose world_from_plane =
      bodies_[plane].WorldFromBody() * bodies_[plane].shapes.front().body_from_shape;
  const Vec3 normal = world_from_plane.rotation * Vec3::UnitZ();
  const double height = normal.dot(world_from_plane.translation);
  near_plane_.resize(bodies_.size());
  step.pool->ParallelFor(bodies_.size(), kVisitsPerChunk, [&](std::size_t i) {
    const Body& body = bodies_[i];
    near_plane_[i] = 0;
    if (!body.in_use || body.is_static || !body.awake || body.shapes.empty()) return;
    // A body whose bounding sphere stays clear of the plane by the contact
    // distance has no pair with it to look at.
    const double clearance = normal.dot(body.position) - height - body.bounding_radius;
    near_plane_[i] = clearance < ContactDistance(body, bodies_[plane], step) ? 1 : 0;
  });
  plane_pairs_.clear();
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    if (near_plane_[i]) plane_pairs_.push_back({static_cast<int>(i), static_cast<int>(plane)});
  }
  pair_visits_.resize(plane_pairs_.size());
  step.pool->ParallelFor(plane_pairs_.size(), kVisitsPerChunk, [&](std::size_t k) {
    VisitPair(plane_pairs_[k], step, &pair_visits_[k]);
  });
  for (std::size_t k = 0; k < plane_pairs_.size(); ++k) {
    ListPair(plane_pairs_[k], pair_visits_[k], step);
  }
}

// m; the margin plus the distance the two bodies can close in one step.
double CollisionSystem::ContactDistance(const Body& a, const Body& b,
                                        const StepContext& step) const {
  return ContactMargin(a, b) + ContactReach(a, b, step);
}

// m; the pair's contact margin: at most a fraction of its thinner body.
double CollisionSystem::ContactMargin(const Body& a, const Body& b) const {
  return std::min(settings_.contact_margin,
                  kMarginPerThickness * std::min(a.thickness, b.thickness));
}

// m; a bound on how far two points of the bodies can close in one step:
// their relative speed, each body's turn times its bounding radius, and
// gravity's half g dt^2.
double CollisionSystem::ContactReach(const Body& a, const Body& b, const StepContext& step) const {
  const double closing_speed = (a.linear_velocity - b.linear_velocity).norm() +
                               a.angular_velocity.norm() * a.bounding_radius +
                               b.angular_velocity.norm() * b.bounding_radius;
  return step.dt * closing_speed + 0.5 * step.dt * step.dt * settings_.gravity.norm();
}

// A face-defined manifold between polyhedra carried to the current poses
// (the persistent manifold of Bullet and Box2D): while the relative pose of
// the bodies has moved A's points by at most contact_reuse_distance relative to B
// since the manifold was clipped, each point's surface points and the
// reference normal move with their shapes, and the separation is
// s = n . (p_a - p_b). For a vertex on a face this is the exact distance of
// the vertex to the face's plane, so resting contact sees exact gaps; only
// where clipping would put the points is off, by at most the motion bound
// |dt| + angle r_a (reuse_error).
bool CollisionSystem::ReuseManifold(const Pose& b_from_a, double reach_a,
                                    const Pose& world_from_shape_a, const Pose& world_from_shape_b,
                                    ShapePairContact* entry) const {
  const ManifoldAnchors& anchors = entry->anchors;
  if (!anchors.valid || settings_.contact_reuse_distance <= 0.0) return false;
  const double motion = (b_from_a.translation - anchors.b_from_a.translation).norm() +
                        b_from_a.rotation.angularDistance(anchors.b_from_a.rotation) * reach_a;
  if (!(motion <= settings_.contact_reuse_distance)) return false;
  ContactManifold& manifold = entry->manifold;
  // Two matrices for up to nine rotations.
  const Mat3 rotation_a = world_from_shape_a.rotation.toRotationMatrix();
  const Mat3 rotation_b = world_from_shape_b.rotation.toRotationMatrix();
  manifold.normal_world =
      Multiply(anchors.normal_turns_with_a ? rotation_a : rotation_b, anchors.normal_shape);
  for (int i = 0; i < manifold.point_count; ++i) {
    const Vec3 on_a = Multiply(rotation_a, anchors.on_a[i]) + world_from_shape_a.translation;
    const Vec3 on_b = Multiply(rotation_b, anchors.on_b[i]) + world_from_shape_b.translation;
    manifold.points[i].separation = manifold.normal_world.dot(on_a - on_b);
    manifold.points[i].position_world = 0.5 * (on_a + on_b);
  }
  entry->reuse_error = motion;
  return true;
}

// Records the anchors of a manifold just clipped between two polyhedra with
// a face witness; edge/edge manifolds, spheres and half-spaces are made
// afresh every step.
void CollisionSystem::AnchorManifold(const Pose& b_from_a, const Pose& world_from_shape_a,
                                     const Pose& world_from_shape_b,
                                     ShapePairContact* entry) const {
  ManifoldAnchors& anchors = entry->anchors;
  const ContactManifold& manifold = entry->manifold;
  const SeparatingWitness::Type type = entry->witness.type;
  entry->reuse_error = 0.0;
  anchors.valid = manifold.point_count > 0 && (type == SeparatingWitness::Type::kFaceA ||
                                               type == SeparatingWitness::Type::kFaceB);
  if (!anchors.valid) return;
  anchors.b_from_a = b_from_a;
  anchors.normal_turns_with_a = type == SeparatingWitness::Type::kFaceA;
  const Pose& world_from_reference =
      anchors.normal_turns_with_a ? world_from_shape_a : world_from_shape_b;
  anchors.normal_shape = world_from_reference.rotation.conjugate() * manifold.normal_world;
  const Pose shape_a_from_world = world_from_shape_a.Inverse();
  const Pose shape_b_from_world = world_from_shape_b.Inverse();
  for (int i = 0; i < manifold.point_count; ++i) {
    const ContactPoint& point = manifold.points[i];
    const Vec3 half_gap = 0.5 * point.separation * manifold.normal_world;
    anchors.on_a[i] = shape_a_from_world * (point.position_world + half_gap);
    anchors.on_b[i] = shape_b_from_world * (point.position_world - half_gap);
  }
}

// Body A is the moving one when only one moves, so normals point from the
// static or sleeping body B into A. Contact points are reported up to the
// margin plus the distance the two bodies can close in one step. A shape
// pair last found apart by a gap g is not looked at again while the bodies
// have travelled less than g minus the contact distance since: no point of
// either has moved far enough to bring them within it (conservative
// advancement's bound, kept across steps).
void CollisionSystem::CollideBodies(std::uint32_t body_a, std::uint32_t body_b,
                                    const StepContext& step) {
  MovingBodyFirst(bodies_, &body_a, &body_b);
  const Body& a = bodies_[body_a];
  const Body& b = bodies_[body_b];
  if (articulations_.SkipsPair(a, b)) return;
  // ContactDistance, with the reach found once.
  const double reach = ContactReach(a, b, step);
  const double contact_distance = ContactMargin(a, b) + reach;
  const double travel = a.travel + b.travel;
  const bool compound = a.shapes.size() > 1 || b.shapes.size() > 1;
  // The poses, made once and only for a pair that is looked at.
  bool posed = false;
  Pose world_from_a;
  Pose world_from_b;
  auto pose = [&] {
    if (posed) return;
    world_from_a = a.WorldFromBody();
    world_from_b = b.WorldFromBody();
    posed = true;
  };
  for (std::size_t i = 0; i < a.shapes.size(); ++i) {
    const ShapeDef& shape_a = a.shapes[i];
    for (std::size_t k = 0; k < b.shapes.size(); ++k) {
      const ShapeDef& shape_b = b.shapes[k];
      // Compound bodies: skip shape pairs whose own boxes are apart.
      if (compound && !std::holds_alternative<HalfSpace>(shape_b.geometry)) {
        pose();
        if (!ShapeAabb(shape_a.geometry, world_from_a * shape_a.body_from_shape)
                 .Fattened(contact_distance)
                 .Overlaps(ShapeAabb(shape_b.geometry, world_from_b * shape_b.body_from_shape))) {
          continue;
        }
      }
      if (const auto* mesh = std::get_if<StaticMesh>(&shape_b.geometry)) {
        if (mesh->slot > 0) continue;  // visited with slot 0
        pose();
        CollideMeshSlots(
            {&contact_cache_, step_count_, &b.shapes, body_a, static_cast<std::uint16_t>(i), body_b,
             static_cast<int>(k), travel},
            {&shape_a.geometry, world_from_a * shape_a.body_from_shape, mesh->mesh.get(),
             world_from_b * shape_b.body_from_shape, contact_distance, reach});
        continue;
      }
      ShapePairContact& entry = contact_cache_.Touch(body_a, static_cast<std::uint16_t>(i), body_b,
                                                     static_cast<std::uint16_t>(k), step_count_);
      if (!CullPair(&entry, contact_distance, travel)) {
        narrow_jobs_.push_back({&entry, travel, false});
      }
    }
  }
}

// CollideBodies' work on a pair of single convex shapes whose entry exists:
// it reads the bodies and writes only that entry.
void CollisionSystem::VisitPair(ProxyPair pair, const StepContext& step, PairVisit* visit) {
  *visit = PairVisit();
  auto body_a = static_cast<std::uint32_t>(pair.first);
  auto body_b = static_cast<std::uint32_t>(pair.second);
  MovingBodyFirst(bodies_, &body_a, &body_b);
  const Body& a = bodies_[body_a];
  const Body& b = bodies_[body_b];
  if (articulations_.SkipsPair(a, b)) return;
  if (a.shapes.size() != 1 || b.shapes.size() != 1 ||
      std::holds_alternative<StaticMesh>(b.shapes.front().geometry)) {
    visit->kind = PairVisit::Kind::kInWalk;
    return;
  }
  visit->body_a = body_a;
  visit->body_b = body_b;
  visit->contact_distance = ContactMargin(a, b) + ContactReach(a, b, step);
  visit->travel = a.travel + b.travel;
  visit->entry = contact_cache_.Find(body_a, 0, body_b, 0);
  if (visit->entry == nullptr) {
    visit->kind = PairVisit::Kind::kNew;
    return;
  }
  visit->kind = PairVisit::Kind::kSeen;
  visit->first_visit = ContactCache::MarkSeen(visit->entry, step_count_);
  visit->culled = CullPair(visit->entry, visit->contact_distance, visit->travel);
}

// What the walk on one thread does with a visited pair, in the pairs' order.
void CollisionSystem::ListPair(ProxyPair pair, const PairVisit& visit, const StepContext& step) {
  switch (visit.kind) {
    case PairVisit::Kind::kSkipped:
      return;
    case PairVisit::Kind::kInWalk:
      CollideBodies(static_cast<std::uint32_t>(pair.first), static_cast<std::uint32_t>(pair.second),
                    step);
      return;
    case PairVisit::Kind::kSeen:
      if (visit.first_visit) contact_cache_.ListVisit(visit.entry);
      if (!visit.culled) narrow_jobs_.push_back({visit.entry, visit.travel, false});
      return;
    case PairVisit::Kind::kNew: {
      ShapePairContact& entry = contact_cache_.Touch(visit.body_a, 0, visit.body_b, 0, step_count_);
      if (!CullPair(&entry, visit.contact_distance, visit.travel)) {
        narrow_jobs_.push_back({&entry, visit.travel, false});
      }
      return;
    }
  }
}

// The poses are made from the bodies as CollideBodies would make them, so a
// pair's test gives the same manifold wherever it runs.
void CollisionSystem::CollideShapePair(NarrowJob* job) const {
  ShapePairContact& entry = *job->entry;
  const Body& a = bodies_[entry.body_a];
  const Body& b = bodies_[entry.body_b];
  const ShapeDef& shape_a = a.shapes[entry.shape_a];
  const ShapeDef& shape_b = b.shapes[entry.shape_b];
  const Pose b_from_a = b.WorldFromPrincipal().Inverse() * a.WorldFromPrincipal();
  const Pose world_from_shape_a = WorldFromShape(a, shape_a);
  const Pose world_from_shape_b = WorldFromShape(b, shape_b);
  if (ReuseManifold(b_from_a, a.bounding_radius, world_from_shape_a, world_from_shape_b, &entry)) {
    job->reused = true;
    MatchWarmStarts(&entry);
    return;
  }
  CollideInput input;
  input.a = &shape_a.geometry;
  input.world_from_a = world_from_shape_a;
  input.b = &shape_b.geometry;
  input.world_from_b = world_from_shape_b;
  input.contact_distance = entry.contact_distance;
  CollideStats stats;
  Collide(input, &entry.witness, &entry.manifold, &stats);
  entry.apart_gap =
      entry.manifold.point_count == 0 ? stats.gap : -std::numeric_limits<double>::infinity();
  entry.apart_travel = job->travel;
  AnchorManifold(b_from_a, world_from_shape_a, world_from_shape_b, &entry);
  MatchWarmStarts(&entry);
}

// The pair's manifold clipped afresh at the current poses.
void CollisionSystem::RecollidePair(const StepContext& step, ShapePairContact* pair) {
  const Body& a = bodies_[pair->body_a];
  const Body& b = bodies_[pair->body_b];
  const ShapeDef& shape_a = a.shapes[pair->shape_a];
  const ShapeDef& shape_b = b.shapes[pair->shape_b];
  CollideInput input;
  input.a = &shape_a.geometry;
  input.world_from_a = WorldFromShape(a, shape_a);
  input.b = &shape_b.geometry;
  input.world_from_b = WorldFromShape(b, shape_b);
  input.contact_distance = ContactDistance(a, b, step);
  pair->contact_distance = input.contact_distance;
  CollideStats stats;
  Collide(input, &pair->witness, &pair->manifold, &stats);
  pair->apart_gap =
      pair->manifold.point_count == 0 ? stats.gap : -std::numeric_limits<double>::infinity();
  pair->apart_travel = a.travel + b.travel;
  pair->anchors.valid = false;
}

}  // namespace rigid_body_sim::physics
