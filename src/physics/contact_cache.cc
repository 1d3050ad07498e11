#include "rigid_body_sim/physics/contact_cache.h"

#include <algorithm>
#include <cassert>

namespace rigid_body_sim::physics {

// 20 bits per body slot and 12 per shape: up to a million bodies with up to
// 4096 shapes each.
std::uint64_t ContactCache::Key(std::uint32_t body_a, std::uint16_t shape_a, std::uint32_t body_b,
                                std::uint16_t shape_b) {
  assert(body_a < (1u << 20) && body_b < (1u << 20) && shape_a < 4096 && shape_b < 4096);
  return (std::uint64_t{body_a} << 44) | (std::uint64_t{body_b} << 24) |
         (std::uint64_t{shape_a} << 12) | std::uint64_t{shape_b};
}

ShapePairContact& ContactCache::Touch(std::uint32_t body_a, std::uint16_t shape_a,
                                      std::uint32_t body_b, std::uint16_t shape_b,
                                      std::uint64_t step) {
  auto [it, inserted] = pairs_.try_emplace(Key(body_a, shape_a, body_b, shape_b));
  ShapePairContact& entry = it->second;
  if (inserted) {
    entry.body_a = body_a;
    entry.body_b = body_b;
    entry.shape_a = shape_a;
    entry.shape_b = shape_b;
  }
  entry.last_seen_step = step;
  return entry;
}

void ContactCache::MatchAndPrune(std::uint64_t step,
                                 const std::function<bool(const ShapePairContact&)>& asleep) {
  touching_.clear();
  seen_.clear();
  sleeping_.clear();
  for (auto it = pairs_.begin(); it != pairs_.end();) {
    ShapePairContact& entry = it->second;
    if (entry.last_seen_step != step) {
      if (entry.previous_count > 0 && asleep(entry)) {
        sleeping_.push_back(&entry);
        ++it;
      } else {
        it = pairs_.erase(it);
      }
      continue;
    }
    for (int i = 0; i < entry.manifold.point_count; ++i) {
      CachedImpulse& warm = entry.warm_start[i];
      warm = CachedImpulse{entry.manifold.points[i].feature, 0.0, {0.0, 0.0}};
      for (int k = 0; k < entry.previous_count; ++k) {
        if (entry.previous[k].feature == warm.feature) {
          warm = entry.previous[k];
          break;
        }
      }
    }
    seen_.push_back(&entry);
    if (entry.manifold.point_count > 0) {
      touching_.push_back(&entry);
    } else {
      entry.previous_count = 0;
    }
    ++it;
  }
  // Hash-map order depends on the insertion history; the solver's
  // Gauss-Seidel order should not.
  auto by_key = [](const ShapePairContact* x, const ShapePairContact* y) {
    return Key(x->body_a, x->shape_a, x->body_b, x->shape_b) <
           Key(y->body_a, y->shape_a, y->body_b, y->shape_b);
  };
  std::sort(touching_.begin(), touching_.end(), by_key);
  std::sort(seen_.begin(), seen_.end(), by_key);
  std::sort(sleeping_.begin(), sleeping_.end(), by_key);
}

void ContactCache::RemoveBody(std::uint32_t body) {
  for (auto it = pairs_.begin(); it != pairs_.end();) {
    if (it->second.body_a == body || it->second.body_b == body) {
      it = pairs_.erase(it);
    } else {
      ++it;
    }
  }
  touching_.clear();
  seen_.clear();
  sleeping_.clear();
}

void ContactCache::Clear() {
  pairs_.clear();
  touching_.clear();
  seen_.clear();
  sleeping_.clear();
}

}  // namespace rigid_body_sim::physics
