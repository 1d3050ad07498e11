#include "physics/contact/contact_cache.h"

#include <algorithm>
#include <cassert>

namespace rigid_body_sim::physics {
namespace {

// m; how far a point may be from one of last step's to take its impulses
// when their features differ. Resting points move far less in a step.
constexpr double kPositionMatchDistance = 1e-3;

// A key's body A: its top 20 bits (ContactCache::Key); body B the 20 below
// them.
constexpr int kBodyAShift = 44;
constexpr int kBodyBShift = 24;
constexpr std::uint32_t kBodyMask = (1u << 20) - 1;

}  // namespace

void SortByPairKey(std::vector<KeyedPair>* keyed, std::vector<KeyedPair>* scratch,
                   std::vector<std::uint32_t>* starts) {
  if (keyed->size() < 2) return;
  std::uint64_t last_body = 0;
  for (const KeyedPair& pair : *keyed) last_body = std::max(last_body, pair.first >> kBodyAShift);
  // starts[b + 1] counts body b's pairs, then their sums place each body.
  starts->assign(last_body + 2, 0);
  for (const KeyedPair& pair : *keyed) ++(*starts)[(pair.first >> kBodyAShift) + 1];
  for (std::size_t b = 1; b < starts->size(); ++b) (*starts)[b] += (*starts)[b - 1];
  scratch->resize(keyed->size());
  for (const KeyedPair& pair : *keyed) (*scratch)[(*starts)[pair.first >> kBodyAShift]++] = pair;
  for (std::size_t i = 1; i < scratch->size(); ++i) {
    const KeyedPair pair = (*scratch)[i];
    std::size_t k = i;
    for (; k > 0 && pair.first < (*scratch)[k - 1].first; --k) (*scratch)[k] = (*scratch)[k - 1];
    (*scratch)[k] = pair;
  }
  keyed->swap(*scratch);
}

// Each point of this step's manifold takes the impulses of last step's point
// with the same features, else of the nearest unmatched one; a pair with no
// point this step keeps none for the next.
void MatchWarmStarts(ShapePairContact* entry) {
  entry->warm_from = {-1, -1, -1, -1};
  if (entry->manifold.point_count == 0) {
    entry->previous_count = 0;
    return;
  }
  std::array<bool, ContactManifold::kMaxPoints> taken{};  // previous points matched
  for (int i = 0; i < entry->manifold.point_count; ++i) {
    for (int k = 0; k < entry->previous_count; ++k) {
      if (entry->previous[k].feature == entry->manifold.points[i].feature) {
        entry->warm_from[i] = static_cast<std::int8_t>(k);
        taken[k] = true;
        break;
      }
    }
  }
  // A manifold clipped afresh can name the same contact by other features
  // (two parallel faces: either may be the reference); such a point takes
  // the impulses of the nearest unmatched point of last step within
  // kPositionMatchDistance, as a persistent manifold matches by distance.
  for (int i = 0; i < entry->manifold.point_count; ++i) {
    if (entry->warm_from[i] >= 0) continue;
    const Vec3& position = entry->manifold.points[i].position_world;
    int nearest = -1;
    double nearest_squared = kPositionMatchDistance * kPositionMatchDistance;
    for (int k = 0; k < entry->previous_count; ++k) {
      const double squared = (entry->previous[k].position_world - position).squaredNorm();
      if (!taken[k] && squared < nearest_squared) {
        nearest = k;
        nearest_squared = squared;
      }
    }
    if (nearest < 0) continue;
    taken[nearest] = true;
    entry->warm_from[i] = static_cast<std::int8_t>(nearest);
  }
}

// 20 bits per body slot and 12 per shape: up to a million bodies with up to
// 4096 shapes each.
std::uint64_t ContactCache::Key(std::uint32_t body_a, std::uint16_t shape_a, std::uint32_t body_b,
                                std::uint16_t shape_b) {
  assert(body_a < (1u << 20) && body_b < (1u << 20) && shape_a < 4096 && shape_b < 4096);
  return (std::uint64_t{body_a} << kBodyAShift) | (std::uint64_t{body_b} << kBodyBShift) |
         (std::uint64_t{shape_a} << 12) | std::uint64_t{shape_b};
}

void ContactCache::PrefetchPair(Prefetch stage, std::uint32_t body_a, std::uint16_t shape_a,
                                std::uint32_t body_b, std::uint16_t shape_b) const {
  const std::uint64_t key = Key(body_a, shape_a, body_b, shape_b);
  if (stage == Prefetch::kSlot) {
    index_.PrefetchSlot(key);
  } else if (const ShapePairContact* entry = index_.Find(key)) {
    __builtin_prefetch(entry);
  }
}

ShapePairContact& ContactCache::Touch(std::uint32_t body_a, std::uint16_t shape_a,
                                      std::uint32_t body_b, std::uint16_t shape_b,
                                      std::uint64_t step) {
  const std::uint64_t key = Key(body_a, shape_a, body_b, shape_b);
  ShapePairContact* entry = index_.Find(key);
  if (entry == nullptr) {
    // A frozen pair comes back with its witness and impulses.
    if (auto frozen = frozen_.find(key); frozen != frozen_.end()) {
      entry = &pairs_.insert(frozen_.extract(frozen)).position->second;
      frozen_changed_ = true;
    } else {
      entry = &pairs_.try_emplace(key).first->second;
      entry->key = key;
      entry->body_a = body_a;
      entry->body_b = body_b;
      entry->shape_a = shape_a;
      entry->shape_b = shape_b;
    }
    // Map nodes do not move, so the pointer stays good until the pair is erased.
    index_.Insert(key, entry);
  }
  if (MarkSeen(entry, step)) ListVisit(entry);
  return *entry;
}

ShapePairContact* ContactCache::Find(std::uint32_t body_a, std::uint16_t shape_a,
                                     std::uint32_t body_b, std::uint16_t shape_b) const {
  return index_.Find(Key(body_a, shape_a, body_b, shape_b));
}

void ContactCache::Prune(std::uint64_t step, bool recheck_frozen,
                         const std::function<bool(const ShapePairContact&)>& asleep) {
  if (recheck_frozen) {
    for (auto it = frozen_.begin(); it != frozen_.end();) {
      if (asleep(it->second)) {
        ++it;
      } else {
        it = frozen_.erase(it);
        frozen_changed_ = true;
      }
    }
  }
  // Every pair was seen this step unless there are more pairs than visits;
  // only then do the unseen ones have to be found and dropped or frozen.
  // They are among last step's seen_, which holds every pair older than
  // this step: a walk of that list loads the entries independently of each
  // other, where a walk of the map would chase its nodes one by one.
  if (pairs_.size() > visited_.size()) {
    for (ShapePairContact* entry : seen_) {
      if (entry->last_seen_step == step) continue;
      const std::uint64_t key = entry->key;
      index_.Erase(key);
      if (entry->previous_count > 0 && asleep(*entry)) {
        frozen_.insert(pairs_.extract(key));
        frozen_changed_ = true;
      } else {
        pairs_.erase(key);
      }
    }
  }
  assert(pairs_.size() == visited_.size());
  // The narrow phase's visits come in a deterministic order (sorted pairs,
  // then the half-space pairs by body).
  seen_.swap(visited_);
  visited_.clear();
}

void ContactCache::ListTouching(TaskPool* pool) {
  touching_.clear();
  keyed_.clear();
  // The entries are read on the pool (each a load the caches no longer
  // hold), the touching ones listed here from what they gave.
  constexpr std::size_t kEntriesPerChunk = 256;
  seen_keys_.resize(seen_.size());
  pool->ParallelFor(seen_.size(), kEntriesPerChunk, [this](std::size_t m) {
    ShapePairContact* entry = seen_[m];
    seen_keys_[m] = KeyedPair{entry->key, entry->manifold.point_count > 0 ? entry : nullptr};
  });
  for (const KeyedPair& seen : seen_keys_) {
    if (seen.second != nullptr) keyed_.push_back(seen);
  }
  // The solver's Gauss-Seidel order is the key order (body A's index first),
  // whatever order the pairs were visited in. The keys sit next to the
  // pointers, so the sort does not chase them.
  SortByPairKey(&keyed_, &sorted_, &body_starts_);
  touching_bodies_.clear();
  for (const auto& [key, entry] : keyed_) {
    touching_.push_back(entry);
    touching_bodies_.push_back({static_cast<std::uint32_t>(key >> kBodyAShift),
                                static_cast<std::uint32_t>(key >> kBodyBShift) & kBodyMask});
  }
  if (frozen_changed_) ListSleeping();
}

bool ContactCache::KeyLess(const ShapePairContact* x, const ShapePairContact* y) {
  return x->key < y->key;
}

void ContactCache::ListSleeping() {
  sleeping_.clear();
  for (const auto& [key, entry] : frozen_) sleeping_.push_back(&entry);
  std::sort(sleeping_.begin(), sleeping_.end(), KeyLess);
  frozen_changed_ = false;
  ++sleeping_version_;
}

void ContactCache::RemoveBody(std::uint32_t body) {
  // seen_ goes on listing every pair of pairs_ (Prune looks there
  // for the unseen ones), so the body's pairs leave it before they go.
  auto of_body = [body](const ShapePairContact* entry) {
    return entry->body_a == body || entry->body_b == body;
  };
  seen_.erase(std::remove_if(seen_.begin(), seen_.end(), of_body), seen_.end());
  for (PairMap* map : {&pairs_, &frozen_}) {
    for (auto it = map->begin(); it != map->end();) {
      if (of_body(&it->second)) {
        if (map == &pairs_) index_.Erase(it->first);
        it = map->erase(it);
      } else {
        ++it;
      }
    }
  }
  touching_.clear();
  visited_.clear();
  ListSleeping();
}

void ContactCache::Clear() {
  pairs_.clear();
  index_.Clear();
  frozen_.clear();
  touching_.clear();
  seen_.clear();
  visited_.clear();
  ListSleeping();
}

}  // namespace rigid_body_sim::physics
