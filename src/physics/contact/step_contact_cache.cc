// Stage 3 of WorldImpl::Step: match this step's contact points with last step's
// for warm starting, forget vanished pairs, and wake sleeping bodies that an
// awake body touches.
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {

namespace {

// Pairs a thread matches at a time.
constexpr std::size_t kPairsPerChunk = 256;

}  // namespace

void WorldImpl::UpdateContactCache(const StepContext& step) {
  contact_cache_.Prune(step_count_, woke_since_prune_, [this](const ShapePairContact& pair) {
    const Body& a = bodies_[pair.body_a];
    const Body& b = bodies_[pair.body_b];
    return (a.is_static || (!a.awake && !a.disabled)) && (b.is_static || (!b.awake && !b.disabled));
  });
  woke_since_prune_ = false;
  // Each pair's match reads and writes only its own entry, so the pool's
  // threads may share them in any order.
  const std::vector<ShapePairContact*>& seen = contact_cache_.seen();
  step.pool->ParallelFor(seen.size(), kPairsPerChunk, [&](std::size_t e) {
    PrefetchAhead(seen, e, PrefetchPoints);
    MatchWarmStarts(seen[e]);
  });
  contact_cache_.ListTouching();
  for (const ShapePairContact* pair : contact_cache_.touching()) {
    Body& a = bodies_[pair->body_a];
    Body& b = bodies_[pair->body_b];
    // Either side may be the sleeper: a link closing on a box that sleeps
    // on the table, whatever their order in the pair.
    if (!b.is_static && !b.awake && a.awake) Wake(pair->body_b);
    if (!a.is_static && !a.awake && b.awake) Wake(pair->body_a);
  }
}

}  // namespace rigid_body_sim::physics
