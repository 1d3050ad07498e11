// Stage 1 of WorldImpl::Step: every body's swept, fattened box goes to the
// sort-and-sweep broad phase, which returns the candidate pairs.
#include <variant>

#include "physics/geometry/shape_bounds.h"
#include "physics/world/world_impl.h"

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
  const Pose world_from_body = body->WorldFromBody();
  Aabb box;
  for (std::size_t i = 0; i < body->shapes.size(); ++i) {
    const Aabb shape_box =
        ShapeAabb(body->shapes[i].geometry, world_from_body * body->shapes[i].body_from_shape,
                  &body->box_support[i]);
    box = i == 0 ? shape_box : box.Union(shape_box);
  }
  return box;
}

ProxyKind KindOf(const Body& body) {
  if (body.is_static) return ProxyKind::kStatic;
  return body.awake ? ProxyKind::kDynamic : ProxyKind::kSleeping;
}

}  // namespace

void WorldImpl::UpdateBroadPhase(const StepContext& step) {
  const double margin = settings_.contact_margin;
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    Body& body = bodies_[i];
    if (!body.in_use || body.disabled || body.shapes.empty() ||
        std::holds_alternative<HalfSpace>(body.shapes.front().geometry)) {
      continue;
    }
    const ProxyKind kind = KindOf(body);
    const bool moving = kind == ProxyKind::kDynamic;
    if (body.has_proxy && !moving && broad_phase_.GetKind(static_cast<int>(i)) == kind) continue;
    Aabb box = BodyAabb(&body);
    if (moving) {
      // The box swept over the predicted motion of the step, so that pairs
      // exist before the surfaces meet (and fast bodies cannot skip them).
      const Vec3 motion =
          step.dt * body.linear_velocity + 0.5 * step.dt * step.dt * settings_.gravity;
      box = box.Union(Aabb{box.min + motion, box.max + motion});
      box = box.Fattened(margin + step.dt * body.angular_velocity.norm() * body.bounding_radius);
    } else {
      box = box.Fattened(margin);
    }
    if (!body.has_proxy) {
      broad_phase_.AddProxyWithId(static_cast<int>(i), box, kind,
                                  articulations_.CollisionGroup(body));
      body.has_proxy = true;
    } else {
      broad_phase_.SetAabb(static_cast<int>(i), box);
      broad_phase_.SetKind(static_cast<int>(i), kind);
    }
  }
  broad_phase_.Update();
}

}  // namespace rigid_body_sim::physics
