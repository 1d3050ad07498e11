// Stage 3 of a step: contacts carried from one step to the next.
//
// Per pair of shapes the broad phase reports, the cache keeps the separating
// witness (Baraff's cached defining face or edge: Baraff 1997,
// "Rigid Body Simulation II", section 7.1) and the
// impulses of last step's contact points, so the narrow phase tests the
// witness first and the solver starts from last step's impulses.
#ifndef RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_CACHE_H_
#define RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_CACHE_H_

#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "physics/collision/pair_index.h"
#include "physics/contact/contact_manifold.h"
#include "physics/world/task_pool.h"

namespace rigid_body_sim::physics {

struct CachedImpulse {
  FeatureId feature;
  double normal_impulse = 0.0;              // N s
  std::array<double, 2> tangent_impulse{};  // N s, in the manifold's tangent basis
  Vec3 position_world = Vec3::Zero();       // m, where the point was; set in `previous`
  // N s per step: the load the soft step's contact spring carries at its
  // rest length (soft_contact_solver.h); the exact solver leaves it 0.
  double preload = 0.0;
  // m/s, < 0: the soft step saw the point closing at this speed at the end
  // of the step, before it touched; its restitution answers it next step.
  double approach_velocity = 0.0;
};

// What a manifold between two polyhedra needs to be carried to a nearby
// relative pose without clipping again: each point's two surface points as
// material points of the shapes, and the reference face's normal in its own
// shape's frame.
struct ManifoldAnchors {
  bool valid = false;
  Pose b_from_a;  // principal frames of the bodies, when computed
  bool normal_turns_with_a = true;
  Vec3 normal_shape = Vec3::UnitZ();                     // unit, reference shape frame
  std::array<Vec3, ContactManifold::kMaxPoints> on_a{};  // m, A's shape frame
  std::array<Vec3, ContactManifold::kMaxPoints> on_b{};  // m, B's shape frame
};

// Where a manifold's static friction holds: a material point of each body
// (principal frames) that were together when the contact began to stick.
// While friction holds, the solve pulls them back together, so a stack at
// rest does not creep however many sub-steps its friction takes to settle;
// once friction slips, the anchors start again where the contact is. The
// soft step's (soft_contact_solver.h); the exact solver converges its
// friction every step and needs none.
struct FrictionAnchor {
  bool valid = false;
  Vec3 on_a = Vec3::Zero();  // m, A's principal frame
  Vec3 on_b = Vec3::Zero();
};

struct ShapePairContact {
  // The fields every visit reads first, together in one cache line.
  std::uint64_t key = 0;     // ContactCache's key of the four indices below
  std::uint32_t body_a = 0;  // body slot indices
  std::uint32_t body_b = 0;
  std::uint16_t shape_a = 0;
  std::uint16_t shape_b = 0;
  std::uint64_t last_seen_step = 0;
  // m; the narrow phase reported points closer than this, so with none the
  // shapes are at least this far apart.
  double contact_distance = 0.0;
  // With no points: a lower bound on the shapes' distance when the pair was
  // last tested (m, -infinity when not known), and the summed travel of the
  // two bodies then (Body::travel).
  double apart_gap = -std::numeric_limits<double>::infinity();
  double apart_travel = 0.0;
  // Last step's points (previous), in the first line for a culled pair's
  // match.
  int previous_count = 0;
  SeparatingWitness witness;
  ContactManifold manifold;  // this step's
  ManifoldAnchors anchors;
  // m; how far the reused manifold's points may be from where clipping would
  // put them (0 when the manifold was clipped this step).
  double reuse_error = 0.0;
  // Which of last step's points each of this step's points starts from,
  // -1 for none (MatchWarmStarts): an index, not a copy, so that a step
  // moves 4 bytes a point here instead of the impulses' 72.
  std::array<std::int8_t, ContactManifold::kMaxPoints> warm_from{-1, -1, -1, -1};
  // Last step's points and their final impulses.
  std::array<CachedImpulse, ContactManifold::kMaxPoints> previous{};
  FrictionAnchor friction_anchor;

  // The impulses this step's point i starts from: those of last step's
  // point it matched, or none. Valid until this step's impulses are kept
  // (ContactReports::ReportSolved), which overwrites `previous`.
  const CachedImpulse& WarmStart(int i) const {
    static const CachedImpulse kNone{};
    return warm_from[i] < 0 ? kNone : previous[warm_from[i]];
  }
};

// Entries ahead of the one in use whose lines a walk over entries starts
// loading (PrefetchManifold, PrefetchPoints): the entries, about 1 kB each,
// are scattered over more memory than the caches hold.
constexpr std::size_t kEntryPrefetchDistance = 4;

inline void PrefetchBytes(const void* begin, std::size_t size) {
  const char* bytes = static_cast<const char*>(begin);
  for (std::size_t offset = 0; offset < size; offset += 64) __builtin_prefetch(bytes + offset);
}

// Starts loading the visit fields and the manifold of an entry.
inline void PrefetchManifold(const ShapePairContact& entry) {
  PrefetchBytes(&entry, offsetof(ShapePairContact, manifold) + sizeof(entry.manifold));
}

// Starts loading what a narrow-phase test of an entry reads and writes: the
// visit fields, the witness and the manifold, the anchors a carried
// manifold moves with, and last step's points its warm starts match.
inline void PrefetchCollide(const ShapePairContact& entry) {
  PrefetchBytes(&entry, offsetof(ShapePairContact, previous) + sizeof(entry.previous));
}

// Starts loading what the stages after the narrow phase read and write of
// an entry: the manifold, the warm start and last step's points.
inline void PrefetchPoints(const ShapePairContact& entry) {
  PrefetchBytes(&entry.manifold, sizeof(entry.manifold));
  PrefetchBytes(&entry.warm_from, sizeof(entry.warm_from) + sizeof(entry.previous));
}

// Starts loading the friction anchor of an entry.
inline void PrefetchFrictionAnchor(const ShapePairContact& entry) {
  PrefetchBytes(&entry.friction_anchor, sizeof(entry.friction_anchor));
}

// For a walk over `entries` now at `index`: `prefetch` (PrefetchManifold or
// PrefetchPoints) of the entry kEntryPrefetchDistance ahead, if there is one.
inline void PrefetchAhead(const std::vector<ShapePairContact*>& entries, std::size_t index,
                          void (*prefetch)(const ShapePairContact&)) {
  if (index + kEntryPrefetchDistance < entries.size()) {
    prefetch(*entries[index + kEntryPrefetchDistance]);
  }
}

// A contact cache entry with its key (ContactCache::Key).
using KeyedPair = std::pair<std::uint64_t, ShapePairContact*>;

class ContactCache {
 public:
  // Starts loading what a Touch of the pair will read, some visits before
  // it: kSlot its index slot, kEntry (once the slot is loaded) the entry
  // itself. Changes nothing.
  enum class Prefetch { kSlot, kEntry };
  void PrefetchPair(Prefetch stage, std::uint32_t body_a, std::uint16_t shape_a,
                    std::uint32_t body_b, std::uint16_t shape_b) const;

  // The entry of a shape pair, created empty when new; marks it seen.
  ShapePairContact& Touch(std::uint32_t body_a, std::uint16_t shape_a, std::uint32_t body_b,
                          std::uint16_t shape_b, std::uint64_t step);
  // Touch of a pair that has an entry, in two halves so that the first may
  // run on any thread while nothing creates entries: Find gives the entry
  // (null when there is none, or it is frozen); MarkSeen marks it seen in
  // `step` and says whether that is its first visit of the step, which the
  // caller then lists with ListVisit in its walk's order.
  ShapePairContact* Find(std::uint32_t body_a, std::uint16_t shape_a, std::uint32_t body_b,
                         std::uint16_t shape_b) const;
  static bool MarkSeen(ShapePairContact* entry, std::uint64_t step) {
    const bool first = entry->last_seen_step != step;
    entry->last_seen_step = step;
    return first;
  }
  void ListVisit(ShapePairContact* entry) { visited_.push_back(entry); }
  // Each pair the narrow phase touches has its points matched with last
  // step's (MatchWarmStarts) once its manifold is final, while the entry is
  // in the cache. Stage 3 in two parts: Prune drops the pairs not seen in
  // `step` unless `asleep` says both of their bodies sleep (their contacts
  // still hold, frozen), and lists the seen ones in seen(); ListTouching
  // lists the touching pairs, reading the entries on `pool`.
  // Frozen pairs are set aside and cost nothing per step; pass
  // `recheck_frozen` when a body woke or left since the last call, so that
  // frozen pairs of bodies no longer asleep go.
  void Prune(std::uint64_t step, bool recheck_frozen,
             const std::function<bool(const ShapePairContact&)>& asleep);
  void ListTouching(TaskPool* pool);
  // Pairs with at least one contact point this step, in key order.
  const std::vector<ShapePairContact*>& touching() const { return touching_; }
  // The bodies (A, B) of each pair of touching(), read from their keys: a
  // walk over them loads no entry.
  const std::vector<std::array<std::uint32_t, 2>>& touching_bodies() const {
    return touching_bodies_;
  }
  // Every pair the narrow phase looked at this step, touching or not, in
  // the order it looked at them.
  const std::vector<ShapePairContact*>& seen() const { return seen_; }
  // Pairs of sleeping bodies, with the contacts and impulses they fell asleep with.
  const std::vector<const ShapePairContact*>& sleeping() const { return sleeping_; }
  // Changes whenever sleeping() does.
  std::uint64_t sleeping_version() const { return sleeping_version_; }
  // Forgets the pairs of one body (when it is destroyed or teleported).
  void RemoveBody(std::uint32_t body);
  void Clear();
  std::size_t size() const { return pairs_.size() + frozen_.size(); }

 private:
  using PairMap = std::unordered_map<std::uint64_t, ShapePairContact>;
  static std::uint64_t Key(std::uint32_t body_a, std::uint16_t shape_a, std::uint32_t body_b,
                           std::uint16_t shape_b);
  static bool KeyLess(const ShapePairContact* x, const ShapePairContact* y);
  // Lists the frozen pairs in sleeping_ and bumps its version.
  void ListSleeping();

  PairMap pairs_;                      // pairs the narrow phase looks at
  PairIndex<ShapePairContact> index_;  // key -> entry of pairs_, for Touch
  PairMap frozen_;                     // pairs of two sleeping (or static) bodies
  std::vector<ShapePairContact*> touching_;
  std::vector<std::array<std::uint32_t, 2>> touching_bodies_;
  std::vector<ShapePairContact*> seen_;     // after Prune, every entry of pairs_
  std::vector<ShapePairContact*> visited_;  // Touch's first visits of the step, in order
  // ListTouching's scratch: each seen entry's key, and the entry if it
  // touches (else null); then the touching ones.
  std::vector<KeyedPair> seen_keys_;
  std::vector<KeyedPair> keyed_;
  std::vector<KeyedPair> sorted_;
  std::vector<std::uint32_t> body_starts_;
  std::vector<const ShapePairContact*> sleeping_;
  std::uint64_t sleeping_version_ = 0;
  bool frozen_changed_ = false;  // frozen_ differs from sleeping_
};

// Sorts (key, entry) pairs by ContactCache's keys, which are distinct and
// begin with body A's index (its top 20 bits): a counting sort on body A,
// then an insertion sort, whose moves stay within one body's few pairs.
// O(n + bodies) work instead of a comparison sort's O(n log n), and the
// same order as std::sort. Distribution counting: Knuth, The Art of
// Computer Programming, vol. 3, 2nd ed., 1998, section 5.2, Algorithm D.
// `scratch` and `starts` keep their memory for the next call.
void SortByPairKey(std::vector<KeyedPair>* keyed, std::vector<KeyedPair>* scratch,
                   std::vector<std::uint32_t>* starts);

// Each point of `entry`'s manifold takes last step's impulses of the point
// with the same features, else of the nearest unmatched one (warm start); a
// pair with no point this step keeps none for the next. Reads and writes
// only `entry`.
void MatchWarmStarts(ShapePairContact* entry);
// MatchWarmStarts of a pair the narrow phase culled: its gap was found with
// no point, so it has none, and keeps none for the next step. Reads and
// writes only the entry's first cache line.
inline void MatchCulled(ShapePairContact* entry) {
  assert(entry->manifold.point_count == 0);
  entry->previous_count = 0;
}

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_CACHE_H_
