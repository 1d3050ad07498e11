// Broad phase: which pairs of bodies have overlapping world AABBs.
//
// Sort and sweep with coherence (Baraff 1997, "Rigid Body Simulation II",
// section 7.2: sort and sweep, insertion sort for coherence). Each proxy's
// box contributes a begin and an end endpoint to a sorted list per axis. A pair
// is reported only when its intervals overlap on all three axes (the
// intersection of the per-axis overlaps, not their union).
#ifndef RIGID_BODY_SIM_PHYSICS_COLLISION_BROAD_PHASE_H_
#define RIGID_BODY_SIM_PHYSICS_COLLISION_BROAD_PHASE_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "physics/geometry/aabb.h"
#include "rigid_body_sim/physics/result.h"

namespace rigid_body_sim::physics {

// Static and sleeping proxies cannot start a contact by themselves, so a pair
// is reported only when at least one of its proxies is dynamic:
// static-static, static-sleeping and sleeping-sleeping pairs never are.
enum class ProxyKind : std::uint8_t { kDynamic, kStatic, kSleeping };

// A pair is reported when one of its proxies moves and they are not of one
// collision group (group 0 is none: the links of an articulation that does
// not collide with itself share one, so that a coiled 1000-link chain does
// not fill the pair set with pairs the narrow phase would drop).
inline bool PairIsReported(ProxyKind a, ProxyKind b, std::uint32_t group_a, std::uint32_t group_b) {
  return (a == ProxyKind::kDynamic || b == ProxyKind::kDynamic) &&
         (group_a == 0 || group_a != group_b);
}

// An unordered pair of proxy ids, stored with first < second.
struct ProxyPair {
  int first = 0;
  int second = 0;

  friend bool operator==(ProxyPair a, ProxyPair b) {
    return a.first == b.first && a.second == b.second;
  }
  friend bool operator!=(ProxyPair a, ProxyPair b) { return !(a == b); }
  friend bool operator<(ProxyPair a, ProxyPair b) {
    return a.first != b.first ? a.first < b.first : a.second < b.second;
  }
};

// One proxy for the reference broad phase.
struct ProxyState {
  int id = 0;
  Aabb aabb_world;
  ProxyKind kind = ProxyKind::kDynamic;
  std::uint32_t group = 0;
};

// Sorts distinct pair keys (a << 32 | b) ascending, as std::sort would: two
// stable counting sorts, by b and then by a (least significant digit first),
// in O(n + m) for ids below m, against std::sort's O(n log n). With an id
// past 4 n + 1024 the counts would outgrow the keys, and std::sort is used.
void SortPairKeys(std::vector<std::uint64_t>* keys);

// Incremental sort-and-sweep broad phase.
//
// Usage per step: SetAabb() for the proxies that moved (and AddProxy,
// RemoveProxy, SetKind as needed), then Update(), then read Pairs().
//
// The first Update() sorts each axis from scratch (std::sort) and sweeps.
// Later updates keep the endpoint lists from the last step and re-sort them
// by insertion sort, which costs O(n + swaps) when motion is coherent. Each
// swap of a begin past an end changes the overlap of one pair on one axis
// only, so the pair set is updated on the swap: a begin moving before an end
// may start an overlap (the other two axes are tested directly), an end moving
// before a begin ends one. When many proxies were added since the last
// update, the lists are sorted from scratch again instead.
//
// Pairs of a removed proxy are dropped at once; every other change shows in
// the pairs after the next Update().
class SortAndSweepBroadPhase {
 public:
  // Ids are array indices, so they are bounded to keep memory proportional
  // to the number of proxies.
  static constexpr int kMaxProxyId = (1 << 24) - 1;

  // Adds a proxy under an unused id (ids of removed proxies are reused first)
  // and returns the id. Refuses a box that is not finite or has min > max.
  // `group` is its collision group for good (PairIsReported).
  Result<int> AddProxy(const Aabb& aabb_world, ProxyKind kind, std::uint32_t group = 0);
  // Adds a proxy under an id the caller chooses, in [0, kMaxProxyId]. Refuses
  // an id in use, an id out of range and an invalid box.
  Status AddProxyWithId(int id, const Aabb& aabb_world, ProxyKind kind, std::uint32_t group = 0);
  // Removes the proxy and every pair it is in.
  Status RemoveProxy(int id);
  // Moves the proxy's box; refuses an invalid box and keeps the old one.
  Status SetAabb(int id, const Aabb& aabb_world);
  // Changes the proxy's kind (e.g. a body falls asleep or wakes up).
  Status SetKind(int id, ProxyKind kind);

  // Re-sorts the endpoints and brings the pair set up to date.
  void Update();

  bool Contains(int id) const;
  std::size_t ProxyCount() const { return proxy_count_; }
  // Entries of the free-id list; never more than the ids ever used.
  std::size_t FreeIdCount() const { return free_ids_.size(); }
  const Aabb& GetAabb(int id) const;  // id must be in use (asserted)
  ProxyKind GetKind(int id) const;    // id must be in use (asserted)

  // The current pairs, sorted by (first, second) so that the narrow phase
  // visits them in a deterministic order. Sorted again only after the set
  // changed; the reference holds until the next change.
  const std::vector<ProxyPair>& Pairs() const;
  std::size_t PairCount() const { return pairs_.size(); }
  bool HasPair(int a, int b) const;

  // Adjacent endpoint swaps done by the insertion sorts of the last Update()
  // (0 after a rebuild from scratch); the incremental update costs
  // O(n + swaps).
  std::size_t last_update_swaps() const { return last_update_swaps_; }

 private:
  // One end of a proxy's interval on one axis. Sorted by value; at equal
  // values begins come before ends, which makes touching intervals overlap
  // (closed intervals, as Aabb::Overlaps).
  struct Endpoint {
    double value;          // m, world; copied from the box by Update()
    std::uint32_t proxy;   // id, or kDeadProxy once the proxy was removed
    std::uint32_t is_end;  // 0 = begin (min), 1 = end (max)
  };
  static constexpr std::uint32_t kDeadProxy = 0xffffffffu;

  struct Proxy {
    Aabb aabb_world;
    // endpoint[2 * axis + is_end]: index of the endpoint in endpoints_[axis].
    std::array<std::uint32_t, 6> endpoint{};
    ProxyKind kind = ProxyKind::kDynamic;
    std::uint32_t group = 0;
    bool in_use = false;
    // Added since the last Update(): its endpoints sit unsorted at the end
    // of the lists and it is in no pair yet.
    bool pending = false;
    // Its id is in free_ids_ (at most once, so the list never outgrows the
    // slots however often ids chosen by the caller are removed and reused).
    bool in_free_list = false;
  };

  static bool Precedes(const Endpoint& a, const Endpoint& b) {
    return a.value < b.value || (a.value == b.value && a.is_end < b.is_end);
  }
  // begin_a before end_b and begin_b before end_a in the list of the axis.
  static bool OverlapInListOrder(const Proxy& a, const Proxy& b, int axis) {
    return a.endpoint[2 * axis] < b.endpoint[2 * axis + 1] &&
           b.endpoint[2 * axis] < a.endpoint[2 * axis + 1];
  }
  static std::uint64_t PairKey(std::uint32_t a, std::uint32_t b) {
    return a < b ? (std::uint64_t{a} << 32) | b : (std::uint64_t{b} << 32) | a;
  }

  Status CheckId(int id) const;
  // The endpoint's value from its proxy's box (the list holds a copy so
  // that comparisons during the sort stay in the list).
  double CurrentValue(const Endpoint& endpoint, int axis) const;
  // Proxies whose endpoints overlap those of `id` on all three axes in the
  // current list order (the order the pair set agrees with).
  std::vector<std::uint32_t> OverlappingInListOrder(std::uint32_t id) const;
  void RemoveDeadEndpoints();
  void RebuildFromScratch();
  void InsertionSortAxis(int axis);
  // The only ways pairs_ changes, besides RebuildFromScratch's clear, so
  // that Pairs() knows when to sort again and which keys changed.
  void AddPair(std::uint64_t key);
  void ErasePair(std::uint64_t key);
  void NoteChangedPair(std::uint64_t key);
  // sorted_pairs_ brought up to date from the keys changed since it was
  // made: they are sorted, and merged in.
  void MergeChangedPairs() const;

  std::vector<Proxy> proxies_;  // indexed by id
  // Ids below proxies_.size() that were free when listed; AddProxy drops
  // the ones AddProxyWithId has taken since.
  std::vector<std::uint32_t> free_ids_;
  std::array<std::vector<Endpoint>, 3> endpoints_;  // per axis, sorted after Update()
  std::vector<std::uint32_t> pending_ids_;          // added since the last Update()
  std::unordered_set<std::uint64_t> pairs_;         // PairKey of each reported pair
  mutable std::vector<ProxyPair> sorted_pairs_;     // pairs_ as Pairs() returns them
  mutable bool sorted_pairs_stale_ = true;          // pairs_ changed since sorted_pairs_
  // The keys added to or erased from pairs_ since sorted_pairs_ was made (a
  // key may appear more than once), while sorted_pairs_ and they make
  // pairs_ (changes_complete_): a settling pile changes a few percent of
  // its pairs a step, and sorting all of them again was 2 % of pile_4000's
  // step, on one thread.
  mutable std::vector<std::uint64_t> changed_pairs_;
  mutable bool changes_complete_ = false;
  mutable std::vector<ProxyPair> merged_pairs_;  // MergeChangedPairs' scratch
  std::size_t proxy_count_ = 0;
  std::size_t pending_count_ = 0;
  std::size_t last_update_swaps_ = 0;
  std::size_t dead_endpoint_count_ = 0;  // per axis
  bool built_ = false;
  bool boxes_moved_ = false;  // a SetAabb changed a box since the last Update
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_COLLISION_BROAD_PHASE_H_
