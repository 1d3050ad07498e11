// The broad phase's test oracle, built only into the tests (rbs_test_support).
#ifndef RIGID_BODY_SIM_TEST_SUPPORT_BRUTE_FORCE_BROAD_PHASE_H_
#define RIGID_BODY_SIM_TEST_SUPPORT_BRUTE_FORCE_BROAD_PHASE_H_

#include <vector>

#include "physics/collision/broad_phase.h"

namespace rigid_body_sim::physics {

// Reference broad phase: tests every pair directly, O(n^2). Same rules as
// SortAndSweepBroadPhase (closed intervals, overlap on all three axes, at
// least one dynamic proxy). Returns the pairs sorted by (first, second).
// Ids must be distinct and boxes valid (asserted).
std::vector<ProxyPair> BruteForcePairs(const std::vector<ProxyState>& proxies);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_TEST_SUPPORT_BRUTE_FORCE_BROAD_PHASE_H_
