#include "support/brute_force_broad_phase.h"

#include <algorithm>
#include <cassert>

namespace rigid_body_sim::physics {

// Reference for SortAndSweepBroadPhase: every pair of boxes is tested
// directly on all three axes, O(n^2), with the same reporting rule.
std::vector<ProxyPair> BruteForcePairs(const std::vector<ProxyState>& proxies) {
  std::vector<ProxyPair> pairs;
  for (std::size_t i = 0; i < proxies.size(); ++i) {
    const ProxyState& a = proxies[i];
    assert(a.aabb_world.IsValid());
    for (std::size_t j = i + 1; j < proxies.size(); ++j) {
      const ProxyState& b = proxies[j];
      assert(a.id != b.id);
      // All six comparisons without short-circuit: no branch to mispredict,
      // which keeps the O(n^2) loop usable as a per-step test reference.
      bool overlap = true;
      for (int axis = 0; axis < 3; ++axis) {
        overlap &= (a.aabb_world.min[axis] <= b.aabb_world.max[axis]) &
                   (b.aabb_world.min[axis] <= a.aabb_world.max[axis]);
      }
      if (overlap && PairIsReported(a.kind, b.kind, a.group, b.group)) {
        pairs.push_back(ProxyPair{std::min(a.id, b.id), std::max(a.id, b.id)});
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace rigid_body_sim::physics
