// Stage 3 of WorldImpl::Step: forget vanished pairs, list the touching ones
// (whose points the narrow phase matched with last step's for warm
// starting), and wake sleeping bodies that an awake body touches.
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {

void WorldImpl::UpdateContactCache() {
  contact_cache_.Prune(step_count_, woke_since_prune_, [this](const ShapePairContact& pair) {
    const Body& a = bodies_[pair.body_a];
    const Body& b = bodies_[pair.body_b];
    return (a.is_static || (!a.awake && !a.disabled)) && (b.is_static || (!b.awake && !b.disabled));
  });
  woke_since_prune_ = false;
  // The narrow phase has matched each seen pair's points with last step's.
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
