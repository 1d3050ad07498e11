// Stage 1 of World::Step (CollisionSystem): every body's swept, fattened box goes to the
// sort-and-sweep broad phase, which returns the candidate pairs.
#include <algorithm>
#include <variant>

#include "physics/collision/collision_system.h"
#include "physics/dynamics/body_frames.h"
#include "physics/geometry/shape_bounds.h"

namespace rigid_body_sim::physics {
namespace {

// The union of the shapes' boxes. Each polyhedron's support climbs start
// where the last step's ended (Body::box_support): a turning body's extreme
// vertices move a step or two along its edges between two steps.
Aabb BodyAabb(Body* body) {
  if (body->box_support.size() != body->shapes.size()) {
    body->box_support.assign(body->shapes.size(), std::array<int, 6>{});
    for (std::size_t i = 0; i < body->shapes.size(); ++i) {
      const auto* polyhedron =
          std::get_if<std::shared_ptr<const ConvexPolyhedron>>(&body->shapes[i].geometry);
      if (polyhedron != nullptr) body->box_support[i] = (*polyhedron)->axis_support;
    }
  }
  const Pose world_from_body =
      ComposeUnlessIdentity(body->WorldFromPrincipal(), body->principal_from_body);
  Aabb box;
  for (std::size_t i = 0; i < body->shapes.size(); ++i) {
    const Aabb shape_box =
        ShapeAabb(body->shapes[i].geometry,
                  ComposeUnlessIdentity(world_from_body, body->shapes[i].body_from_shape),
                  &body->box_support[i]);
    box = i == 0 ? shape_box : box.Union(shape_box);
  }
  return box;
}

ProxyKind KindOf(const Body& body) {
  if (body.is_static) return ProxyKind::kStatic;
  return body.awake ? ProxyKind::kDynamic : ProxyKind::kSleeping;
}

// A body's proxy box: a moving body's is swept over the step's predicted
// motion, x + dt v + dt^2 g / 2, so that pairs exist before the surfaces
// meet (and fast bodies cannot skip them), and fattened by the margin and
// the turn dt |w| r; any other body's by the margin alone.
Aabb ProxyBox(Body* body, const StepContext& step, const WorldSettings& settings) {
  Aabb box = BodyAabb(body);
  if (KindOf(*body) != ProxyKind::kDynamic) return box.Fattened(settings.contact_margin);
  const Vec3 motion = step.dt * body->linear_velocity + 0.5 * step.dt * step.dt * settings.gravity;
  box = box.Union(Aabb{box.min + motion, box.max + motion});
  return box.Fattened(settings.contact_margin +
                      step.dt * body->angular_velocity.norm() * body->bounding_radius);
}

// Bodies a thread takes at a time: a box costs tens of ns.
constexpr std::size_t kBoxesPerChunk = 128;

// m; how much larger than its body's box a proxy's box is stored, and how
// much more it may be before it is replaced. A body at rest under the soft
// step moves by 1e-12 to 1e-9 m a step (pyramid_90), and each change of a
// box reordered the sort-and-sweep lists among boxes whose faces line up:
// 0.5-1 million endpoint swaps a step. Kept boxes always hold the body's.
constexpr double kBoxSlack = 1e-8;

// Whether `outer` holds `inner`.
bool Holds(const Aabb& outer, const Aabb& inner) {
  return (outer.min.array() <= inner.min.array()).all() &&
         (inner.max.array() <= outer.max.array()).all();
}

}  // namespace

CollisionSystem::CollisionSystem(const WorldParts& world)
    : bodies_(*world.bodies),
      contact_cache_(*world.contact_cache),
      settings_(*world.settings),
      articulations_(*world.articulations) {}

void CollisionSystem::AddBody(std::uint32_t index) {
  const Body& body = bodies_[index];
  if (body.shapes.size() == 1 && std::holds_alternative<HalfSpace>(body.shapes[0].geometry)) {
    half_space_bodies_.push_back(index);
  }
}

void CollisionSystem::RemoveProxy(std::uint32_t index) {
  Body& body = bodies_[index];
  if (!body.has_proxy) return;
  broad_phase_.RemoveProxy(static_cast<int>(index));
  body.has_proxy = false;
}

void CollisionSystem::ForgetBody(std::uint32_t index) {
  RemoveProxy(index);
  half_space_bodies_.erase(std::remove(half_space_bodies_.begin(), half_space_bodies_.end(), index),
                           half_space_bodies_.end());
}

// The bodies that need a box this step are listed in slot order; their
// boxes are made on the pool (a box reads its own body and writes only that
// body's support hints), then handed to the broad phase in the same order,
// so the proxies and their pairs do not depend on the thread count.
void CollisionSystem::UpdateBroadPhase(const StepContext& step) {
  proxy_bodies_.clear();
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    const Body& body = bodies_[i];
    if (!body.in_use || body.disabled || body.shapes.empty() ||
        std::holds_alternative<HalfSpace>(body.shapes.front().geometry)) {
      continue;
    }
    const ProxyKind kind = KindOf(body);
    if (body.has_proxy && kind != ProxyKind::kDynamic &&
        broad_phase_.GetKind(static_cast<int>(i)) == kind) {
      continue;
    }
    proxy_bodies_.push_back(i);
  }
  proxy_boxes_.resize(proxy_bodies_.size());
  step.pool->ParallelFor(proxy_bodies_.size(), kBoxesPerChunk, [&](std::size_t k) {
    proxy_boxes_[k] = ProxyBox(&bodies_[proxy_bodies_[k]], step, settings_);
  });
  for (std::size_t k = 0; k < proxy_bodies_.size(); ++k) {
    const auto id = static_cast<int>(proxy_bodies_[k]);
    Body& body = bodies_[proxy_bodies_[k]];
    const ProxyKind kind = KindOf(body);
    const Aabb& box = proxy_boxes_[k];
    if (!body.has_proxy) {
      broad_phase_.AddProxyWithId(id, box.Fattened(kBoxSlack), kind,
                                  articulations_.CollisionGroup(body));
      body.has_proxy = true;
      continue;
    }
    const Aabb& stored = broad_phase_.GetAabb(id);
    if (!Holds(stored, box) || !Holds(box.Fattened(2.0 * kBoxSlack), stored)) {
      broad_phase_.SetAabb(id, box.Fattened(kBoxSlack));
    }
    broad_phase_.SetKind(id, kind);
  }
  broad_phase_.Update();
}

}  // namespace rigid_body_sim::physics
