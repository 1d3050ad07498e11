#include "physics/collision/broad_phase.h"

#include <algorithm>
#include <cassert>
#include <string>

namespace rigid_body_sim::physics {
namespace {

// When more proxies than this were added since the last Update(), the lists
// are sorted from scratch: each appended endpoint costs O(n) swaps to insert,
// while a full sort costs O(n log n) for all of them together.
constexpr std::size_t kRebuildPendingCount = 32;

Status ValidateAabb(const Aabb& aabb_world) {
  if (!aabb_world.min.allFinite() || !aabb_world.max.allFinite()) {
    return Status::Error("broad phase: AABB has a non-finite corner");
  }
  static constexpr const char* kAxisNames[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    if (aabb_world.min[axis] > aabb_world.max[axis]) {
      return Status::Error(std::string("broad phase: AABB has min > max on axis ") +
                           kAxisNames[axis]);
    }
  }
  return Status::Ok();
}

}  // namespace

Status SortAndSweepBroadPhase::CheckId(int id) const {
  if (!Contains(id)) {
    return Status::Error("broad phase: no proxy with id " + std::to_string(id));
  }
  return Status::Ok();
}

bool SortAndSweepBroadPhase::Contains(int id) const {
  return id >= 0 && static_cast<std::size_t>(id) < proxies_.size() && proxies_[id].in_use;
}

const Aabb& SortAndSweepBroadPhase::GetAabb(int id) const {
  assert(Contains(id));
  return proxies_[id].aabb_world;
}

ProxyKind SortAndSweepBroadPhase::GetKind(int id) const {
  assert(Contains(id));
  return proxies_[id].kind;
}

Result<int> SortAndSweepBroadPhase::AddProxy(const Aabb& aabb_world, ProxyKind kind,
                                             std::uint32_t group) {
  // Ids chosen by the caller may have taken entries of the free list since
  // they were pushed; drop those lazily.
  while (!free_ids_.empty() && proxies_[free_ids_.back()].in_use) {
    proxies_[free_ids_.back()].in_free_list = false;
    free_ids_.pop_back();
  }
  const std::size_t id = free_ids_.empty() ? proxies_.size() : free_ids_.back();
  if (id > static_cast<std::size_t>(kMaxProxyId)) {
    return Result<int>::Error("broad phase: no free proxy id below " +
                              std::to_string(kMaxProxyId + 1));
  }
  const Status status = AddProxyWithId(static_cast<int>(id), aabb_world, kind, group);
  if (!status.ok()) {
    return status;
  }
  return static_cast<int>(id);
}

Status SortAndSweepBroadPhase::AddProxyWithId(int id, const Aabb& aabb_world, ProxyKind kind,
                                              std::uint32_t group) {
  if (id < 0 || id > kMaxProxyId) {
    return Status::Error("broad phase: proxy id " + std::to_string(id) + " is outside [0, " +
                         std::to_string(kMaxProxyId) + "]");
  }
  if (Contains(id)) {
    return Status::Error("broad phase: proxy id " + std::to_string(id) + " is already in use");
  }
  if (Status status = ValidateAabb(aabb_world); !status.ok()) {
    return status;
  }
  const auto slot = static_cast<std::uint32_t>(id);
  if (slot >= proxies_.size()) {
    const auto old_size = static_cast<std::uint32_t>(proxies_.size());
    proxies_.resize(slot + 1);
    // Smallest gap id on top, so AddProxy() hands out low ids first.
    for (std::uint32_t gap = slot; gap-- > old_size;) {
      free_ids_.push_back(gap);
      proxies_[gap].in_free_list = true;
    }
  }
  Proxy& proxy = proxies_[slot];
  const bool listed = proxy.in_free_list;
  proxy = Proxy{};
  proxy.in_free_list = listed;
  proxy.aabb_world = aabb_world;
  proxy.kind = kind;
  proxy.group = group;
  proxy.in_use = true;
  proxy.pending = true;
  // Appended after the sorted part; the next Update() moves the endpoints into
  // place, treating the proxy as if it came from beyond every other box.
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<Endpoint>& list = endpoints_[axis];
    proxy.endpoint[2 * axis] = static_cast<std::uint32_t>(list.size());
    list.push_back(Endpoint{aabb_world.min[axis], slot, 0});
    proxy.endpoint[2 * axis + 1] = static_cast<std::uint32_t>(list.size());
    list.push_back(Endpoint{aabb_world.max[axis], slot, 1});
  }
  pending_ids_.push_back(slot);
  ++pending_count_;
  ++proxy_count_;
  return Status::Ok();
}

Status SortAndSweepBroadPhase::RemoveProxy(int id) {
  if (Status status = CheckId(id); !status.ok()) {
    return status;
  }
  const auto slot = static_cast<std::uint32_t>(id);
  Proxy& proxy = proxies_[slot];
  if (proxy.pending) {
    --pending_count_;  // not sorted in yet, so in no pair
  } else {
    for (std::uint32_t other : OverlappingInListOrder(slot)) {
      ErasePair(PairKey(slot, other));
    }
  }
  // The endpoints stay in the lists, marked, until Update() compacts them in
  // one pass; erasing them here would cost O(n) per removal.
  for (int axis = 0; axis < 3; ++axis) {
    endpoints_[axis][proxy.endpoint[2 * axis]].proxy = kDeadProxy;
    endpoints_[axis][proxy.endpoint[2 * axis + 1]].proxy = kDeadProxy;
  }
  dead_endpoint_count_ += 2;
  proxy.in_use = false;
  proxy.pending = false;
  if (!proxy.in_free_list) {
    free_ids_.push_back(slot);
    proxy.in_free_list = true;
  }
  --proxy_count_;
  return Status::Ok();
}

Status SortAndSweepBroadPhase::SetAabb(int id, const Aabb& aabb_world) {
  if (Status status = CheckId(id); !status.ok()) {
    return status;
  }
  if (Status status = ValidateAabb(aabb_world); !status.ok()) {
    return status;
  }
  // The endpoint values are read back from the boxes when Update() scans the
  // lists in order; writing them here would touch six scattered list entries.
  Aabb& stored = proxies_[id].aabb_world;
  boxes_moved_ |= stored.min != aabb_world.min || stored.max != aabb_world.max;
  stored = aabb_world;
  return Status::Ok();
}

double SortAndSweepBroadPhase::CurrentValue(const Endpoint& endpoint, int axis) const {
  const Aabb& aabb_world = proxies_[endpoint.proxy].aabb_world;
  return endpoint.is_end != 0 ? aabb_world.max[axis] : aabb_world.min[axis];
}

Status SortAndSweepBroadPhase::SetKind(int id, ProxyKind kind) {
  if (Status status = CheckId(id); !status.ok()) {
    return status;
  }
  const auto slot = static_cast<std::uint32_t>(id);
  Proxy& proxy = proxies_[slot];
  const bool was_dynamic = proxy.kind == ProxyKind::kDynamic;
  const bool is_dynamic = kind == ProxyKind::kDynamic;
  proxy.kind = kind;
  // Only pairs with a non-dynamic partner depend on whether this proxy is
  // dynamic; a pending proxy is in no pair until Update() sorts it in.
  if (was_dynamic == is_dynamic || proxy.pending) {
    return Status::Ok();
  }
  for (std::uint32_t other : OverlappingInListOrder(slot)) {
    // A dynamic partner's pair stands either way; one of the same group
    // never does.
    const Proxy& partner = proxies_[other];
    if (partner.kind == ProxyKind::kDynamic || (proxy.group != 0 && partner.group == proxy.group)) {
      continue;
    }
    if (is_dynamic) {
      AddPair(PairKey(slot, other));
    } else {
      ErasePair(PairKey(slot, other));
    }
  }
  return Status::Ok();
}

// The pair set always agrees with the order of the endpoint lists (not with
// box values written since the last Update()), so that the swaps of the next
// insertion sort turn it into the pair set of the new values. Overlap in list
// order on an axis: begin_a before end_b and begin_b before end_a. Scans the x
// list up to the proxy's end: O(n) integer comparisons.
std::vector<std::uint32_t> SortAndSweepBroadPhase::OverlappingInListOrder(std::uint32_t id) const {
  const Proxy& mine = proxies_[id];
  const std::vector<Endpoint>& list_x = endpoints_[0];
  std::vector<std::uint32_t> result;
  for (std::uint32_t i = 0; i < mine.endpoint[1]; ++i) {
    const Endpoint& endpoint = list_x[i];
    if (endpoint.is_end != 0 || endpoint.proxy == kDeadProxy || endpoint.proxy == id) {
      continue;
    }
    const Proxy& other = proxies_[endpoint.proxy];
    if (other.endpoint[1] < mine.endpoint[0]) {
      continue;  // ends before this one begins on x
    }
    if (OverlapInListOrder(mine, other, 1) && OverlapInListOrder(mine, other, 2)) {
      result.push_back(endpoint.proxy);
    }
  }
  return result;
}

void SortAndSweepBroadPhase::RemoveDeadEndpoints() {
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<Endpoint>& list = endpoints_[axis];
    std::uint32_t write = 0;
    for (const Endpoint& endpoint : list) {
      if (endpoint.proxy == kDeadProxy) {
        continue;
      }
      list[write] = endpoint;
      proxies_[endpoint.proxy].endpoint[2 * axis + endpoint.is_end] = write;
      ++write;
    }
    list.resize(write);
  }
  dead_endpoint_count_ = 0;
}

// Sort and sweep from scratch (Baraff 1997, "Rigid Body Simulation II",
// section 7.2.1): sort the endpoints of each axis, then walk one axis keeping the set of open
// intervals; each begin meets exactly the proxies whose intervals are open on that axis, and those
// are tested on all three axes. The walk uses the axis on which the box
// centres spread most, where the fewest intervals are open at once.
void SortAndSweepBroadPhase::RebuildFromScratch() {
  pairs_.clear();
  sorted_pairs_stale_ = true;
  changes_complete_ = false;
  changed_pairs_.clear();
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<Endpoint>& list = endpoints_[axis];
    for (Endpoint& endpoint : list) {
      endpoint.value = CurrentValue(endpoint, axis);
    }
    std::sort(list.begin(), list.end(), Precedes);
    for (std::uint32_t i = 0; i < list.size(); ++i) {
      proxies_[list[i].proxy].endpoint[2 * axis + list[i].is_end] = i;
    }
  }

  Vec3 sum = Vec3::Zero();
  Vec3 sum_of_squares = Vec3::Zero();
  for (const Proxy& proxy : proxies_) {
    if (proxy.in_use) {
      const Vec3 centre = 0.5 * (proxy.aabb_world.min + proxy.aabb_world.max);
      sum += centre;
      sum_of_squares += centre.cwiseProduct(centre);
    }
  }
  const double count = std::max<double>(1.0, static_cast<double>(proxy_count_));
  const Vec3 variance = sum_of_squares / count - (sum / count).cwiseProduct(sum / count);
  int sweep_axis = 0;
  variance.maxCoeff(&sweep_axis);

  std::vector<std::uint32_t> open;
  std::vector<std::uint32_t> slot_in_open(proxies_.size());
  for (const Endpoint& endpoint : endpoints_[sweep_axis]) {
    const std::uint32_t id = endpoint.proxy;
    if (endpoint.is_end == 0) {
      const Proxy& proxy = proxies_[id];
      for (std::uint32_t other : open) {
        const Proxy& other_proxy = proxies_[other];
        if (PairIsReported(proxy.kind, other_proxy.kind, proxy.group, other_proxy.group) &&
            proxy.aabb_world.Overlaps(other_proxy.aabb_world)) {
          AddPair(PairKey(id, other));
        }
      }
      slot_in_open[id] = static_cast<std::uint32_t>(open.size());
      open.push_back(id);
    } else {
      const std::uint32_t last = open.back();
      slot_in_open[last] = slot_in_open[id];
      open[slot_in_open[id]] = last;
      open.pop_back();
    }
  }
}

// Insertion sort of one axis with pair updates on swaps (Baraff 1997,
// "Rigid Body Simulation II", sections 7.2.1-7.2.2: insertion sort of the
// nearly sorted list, overlap changes found at the swaps). Only a swap of a begin with an end
// changes whether two intervals overlap on this axis:
//   begin_a moves before end_b: a and b may now overlap; they are a pair if
//     their new boxes overlap on all three axes;
//   end_a moves before begin_b: a and b are now disjoint on this axis.
// Insertion sort swaps each inverted pair of endpoints exactly once and no
// other, so every pair whose overlap changed on some axis is revisited, and
// the direct box test makes the result independent of the order in which the
// axes are sorted.
//
// The erase in the second case is skipped when the two proxies are disjoint
// in the current list order of another axis d. By induction over the axes in
// the order they are sorted, such a pair is never in the set: if d is not
// sorted yet, they were disjoint on d in the old order, so they were not a
// pair, and nothing added them since (an add needs the new boxes to overlap on
// every axis, and they are disjoint on this one); if d is sorted already, its
// order is final and its own pass left no pair that is disjoint on d. This
// keeps hash look-ups to pairs that are close on all three axes.
//
// Indices in the proxies are fixed after the pass, once per position inside
// the stretches that moved, instead of once per swap.
void SortAndSweepBroadPhase::InsertionSortAxis(int axis) {
  std::vector<Endpoint>& list = endpoints_[axis];
  const int first_slot = 2 * axis;
  const int other_axis_1 = (axis + 1) % 3;
  const int other_axis_2 = (axis + 2) % 3;
  // Positions [stale_begin, stale_end) hold endpoints whose index in the
  // proxy is out of date; stretches that do not touch are flushed one by one.
  std::size_t stale_begin = 0;
  std::size_t stale_end = 0;
  auto flush_stale = [&]() {
    for (std::size_t k = stale_begin; k < stale_end; ++k) {
      proxies_[list[k].proxy].endpoint[first_slot + list[k].is_end] = static_cast<std::uint32_t>(k);
    }
  };
  if (!list.empty()) {
    list[0].value = CurrentValue(list[0], axis);
  }
  for (std::size_t i = 1; i < list.size(); ++i) {
    // Entries before i are already refreshed and sorted.
    list[i].value = CurrentValue(list[i], axis);
    if (!Precedes(list[i], list[i - 1])) {
      continue;
    }
    const Endpoint moving = list[i];
    const Proxy& moving_proxy = proxies_[moving.proxy];
    std::size_t j = i;
    do {
      const Endpoint& passed = list[j - 1];
      assert(passed.proxy != moving.proxy);
      if (moving.is_end != passed.is_end) {
        const Proxy& passed_proxy = proxies_[passed.proxy];
        if (PairIsReported(moving_proxy.kind, passed_proxy.kind, moving_proxy.group,
                           passed_proxy.group)) {
          const std::uint64_t key = PairKey(moving.proxy, passed.proxy);
          if (moving.is_end == 0) {
            if (moving_proxy.aabb_world.Overlaps(passed_proxy.aabb_world)) {
              AddPair(key);
            }
          } else if (OverlapInListOrder(moving_proxy, passed_proxy, other_axis_1) &&
                     OverlapInListOrder(moving_proxy, passed_proxy, other_axis_2)) {
            ErasePair(key);
          }
        }
      }
      list[j] = passed;
      --j;
    } while (j > 0 && Precedes(moving, list[j - 1]));
    list[j] = moving;
    last_update_swaps_ += i - j;
    if (j >= stale_end) {
      flush_stale();
      stale_begin = j;
    } else {
      stale_begin = std::min(stale_begin, j);
    }
    stale_end = i + 1;
  }
  flush_stale();
}

void SortAndSweepBroadPhase::Update() {
  last_update_swaps_ = 0;
  if (dead_endpoint_count_ > 0) {
    RemoveDeadEndpoints();
  }
  if (!built_ || pending_count_ > kRebuildPendingCount) {
    RebuildFromScratch();
  } else if (boxes_moved_ || pending_count_ > 0) {
    // With no box changed and none added the lists are still in order (a
    // sleeping scene costs nothing here).
    for (int axis = 0; axis < 3; ++axis) {
      InsertionSortAxis(axis);
    }
  }
  boxes_moved_ = false;
  for (std::uint32_t id : pending_ids_) {
    proxies_[id].pending = false;
  }
  pending_ids_.clear();
  pending_count_ = 0;
  built_ = true;
}

void SortAndSweepBroadPhase::AddPair(std::uint64_t key) {
  if (pairs_.insert(key).second) NoteChangedPair(key);
}

void SortAndSweepBroadPhase::ErasePair(std::uint64_t key) {
  if (pairs_.erase(key) > 0) NoteChangedPair(key);
}

// Past as many changes as pairs, Pairs() sorts them all again: merging
// would cost more, and the log stays bounded when Pairs() is not called.
void SortAndSweepBroadPhase::NoteChangedPair(std::uint64_t key) {
  sorted_pairs_stale_ = true;
  if (!changes_complete_) return;
  if (changed_pairs_.size() > pairs_.size() + 1024) {
    changes_complete_ = false;
    changed_pairs_.clear();
    return;
  }
  changed_pairs_.push_back(key);
}

namespace {

// keys stably sorted into *sorted by the 32 bits at `shift`, each below m.
void CountingSortBy(const std::vector<std::uint64_t>& keys, int shift, std::uint64_t m,
                    std::vector<std::uint32_t>* counts, std::vector<std::uint64_t>* sorted) {
  counts->assign(m + 1, 0);
  for (const std::uint64_t key : keys) ++(*counts)[((key >> shift) & 0xffffffffu) + 1];
  for (std::uint64_t d = 0; d < m; ++d) (*counts)[d + 1] += (*counts)[d];
  sorted->resize(keys.size());
  for (const std::uint64_t key : keys) (*sorted)[(*counts)[(key >> shift) & 0xffffffffu]++] = key;
}

}  // namespace

// A settling pile's pairs change every step, and std::sort of them was 1.7 %
// of pile_4000's step (perf, one thread).
void SortPairKeys(std::vector<std::uint64_t>* keys) {
  std::uint64_t largest = 0;  // the largest id
  for (const std::uint64_t key : *keys) {
    largest = std::max({largest, key >> 32, key & 0xffffffffu});
  }
  if (largest > 4 * keys->size() + 1024) {
    std::sort(keys->begin(), keys->end());
    return;
  }
  std::vector<std::uint32_t> counts;
  std::vector<std::uint64_t> by_b;
  CountingSortBy(*keys, 0, largest + 1, &counts, &by_b);
  CountingSortBy(by_b, 32, largest + 1, &counts, keys);
}

namespace {

ProxyPair PairOfKey(std::uint64_t key) {
  return ProxyPair{static_cast<int>(key >> 32), static_cast<int>(key & 0xffffffffu)};
}

std::uint64_t KeyOfPair(const ProxyPair& pair) {
  return std::uint64_t{static_cast<std::uint32_t>(pair.first)} << 32 |
         static_cast<std::uint32_t>(pair.second);
}

}  // namespace

const std::vector<ProxyPair>& SortAndSweepBroadPhase::Pairs() const {
  if (!sorted_pairs_stale_) return sorted_pairs_;
  if (changes_complete_) {
    MergeChangedPairs();
  } else {
    std::vector<std::uint64_t> keys(pairs_.begin(), pairs_.end());
    SortPairKeys(&keys);
    sorted_pairs_.clear();
    sorted_pairs_.reserve(keys.size());
    for (std::uint64_t key : keys) sorted_pairs_.push_back(PairOfKey(key));
  }
  changed_pairs_.clear();
  changes_complete_ = true;
  sorted_pairs_stale_ = false;
  return sorted_pairs_;
}

// A merge of two sorted lists: the old pairs whose key did not change, and
// the changed keys that pairs_ holds now (a key added and erased again
// since is in neither). O(n + k log k) for k changes, in the order a full
// sort gives.
void SortAndSweepBroadPhase::MergeChangedPairs() const {
  std::sort(changed_pairs_.begin(), changed_pairs_.end());
  changed_pairs_.erase(std::unique(changed_pairs_.begin(), changed_pairs_.end()),
                       changed_pairs_.end());
  merged_pairs_.clear();
  merged_pairs_.reserve(pairs_.size());
  std::size_t c = 0;
  auto take_changed_below = [&](std::uint64_t bound) {
    for (; c < changed_pairs_.size() && changed_pairs_[c] < bound; ++c) {
      const std::uint64_t changed = changed_pairs_[c];
      if (pairs_.count(changed) > 0) merged_pairs_.push_back(PairOfKey(changed));
    }
  };
  for (const ProxyPair& pair : sorted_pairs_) {
    const std::uint64_t key = KeyOfPair(pair);
    take_changed_below(key);
    if (c < changed_pairs_.size() && changed_pairs_[c] == key) {
      if (pairs_.count(key) > 0) merged_pairs_.push_back(pair);
      ++c;
    } else {
      merged_pairs_.push_back(pair);
    }
  }
  // No key is all ones: a pair's first id is below its second.
  take_changed_below(~std::uint64_t{0});
  sorted_pairs_.swap(merged_pairs_);
}

bool SortAndSweepBroadPhase::HasPair(int a, int b) const {
  if (a < 0 || b < 0 || a == b) {
    return false;
  }
  return pairs_.count(PairKey(static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b))) > 0;
}

}  // namespace rigid_body_sim::physics
