// Stage 3 of WorldImpl::Step: forget vanished pairs, list the touching ones
// (whose points the narrow phase matched with last step's for warm
// starting), and wake sleeping bodies that an awake body touches.
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {

void WorldImpl::UpdateContactCache() {
  // A pair whose bodies are each static or asleep is frozen while unseen.
  auto asleep = [this](const ShapePairContact& pair) {
    const Body& a = bodies_[pair.body_a];
    const Body& b = bodies_[pair.body_b];
    return (a.is_static || (!a.awake && !a.disabled)) && (b.is_static || (!b.awake && !b.disabled));
  };
  contact_cache_.Prune(collision_.step_count(), woke_since_prune_, asleep);
  woke_since_prune_ = false;
  // The narrow phase has matched each seen pair's points with last step's.
  contact_cache_.ListTouching(pool_.get());
  // Either side may be the sleeper: a link closing on a box that sleeps on
  // the table, whatever their order in the pair. The pairs with a sleeper
  // are found on the pool; only they can wake a body, here, in the pairs'
  // order, as a body woken by one pair wakes its sleeping partner in a
  // later one (waking never puts a body to sleep).
  const std::vector<ShapePairContact*>& touching = contact_cache_.touching();
  auto sleeps = [](const Body& body) { return !body.is_static && !body.awake; };
  has_sleeper_.resize(touching.size());
  constexpr std::size_t kPairsPerChunk = 256;
  const std::vector<std::array<std::uint32_t, 2>>& pair_bodies = contact_cache_.touching_bodies();
  pool_->ParallelFor(touching.size(), kPairsPerChunk, [&](std::size_t m) {
    has_sleeper_[m] =
        sleeps(bodies_[pair_bodies[m][0]]) || sleeps(bodies_[pair_bodies[m][1]]) ? 1 : 0;
  });
  for (std::size_t m = 0; m < touching.size(); ++m) {
    if (has_sleeper_[m] == 0) continue;
    const ShapePairContact& pair = *touching[m];
    Body& a = bodies_[pair.body_a];
    Body& b = bodies_[pair.body_b];
    if (sleeps(b) && a.awake) Wake(pair.body_b);
    if (sleeps(a) && b.awake) Wake(pair.body_a);
  }
}

}  // namespace rigid_body_sim::physics
