// Queries of the world between steps.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <variant>
#include <vector>

#include "physics/collision/narrow_phase.h"
#include "physics/geometry/aabb.h"
#include "physics/geometry/shape_bounds.h"
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {
namespace {

// A half-space has no finite box; it is everywhere.
Aabb BoundsOf(const ShapeGeometry& geometry, const Pose& world_from_shape) {
  if (std::holds_alternative<HalfSpace>(geometry)) {
    const double infinity = std::numeric_limits<double>::infinity();
    return Aabb{Vec3::Constant(-infinity), Vec3::Constant(infinity)};
  }
  return ShapeAabb(geometry, world_from_shape);
}

}  // namespace

// Every shape of `id` against every shape of each other enabled body whose
// box it meets, by the narrow phase at zero contact distance: the depth is
// minus the most negative separation. A brute-force pass, since it runs
// once per spawn, not per step.
std::vector<BodyOverlap> WorldImpl::FindOverlaps(BodyId id) const {
  std::vector<BodyOverlap> overlaps;
  if (!IsValid(id) || bodies_[id.index].disabled) return overlaps;
  const Body& body = bodies_[id.index];
  const Pose world_from_body = body.WorldFromBody();
  std::vector<Aabb> boxes;
  for (const ShapeDef& shape : body.shapes) {
    boxes.push_back(BoundsOf(shape.geometry, world_from_body * shape.body_from_shape));
  }
  for (std::uint32_t index = 0; index < bodies_.size(); ++index) {
    const Body& other = bodies_[index];
    if (index == id.index || !other.in_use || other.disabled) continue;
    if (body.is_static && other.is_static) continue;
    const Pose world_from_other = other.WorldFromBody();
    double depth = 0.0;
    for (std::size_t i = 0; i < body.shapes.size(); ++i) {
      const Pose world_from_a = world_from_body * body.shapes[i].body_from_shape;
      for (const ShapeDef& other_shape : other.shapes) {
        const Pose world_from_b = world_from_other * other_shape.body_from_shape;
        if (std::holds_alternative<HalfSpace>(body.shapes[i].geometry) &&
            std::holds_alternative<HalfSpace>(other_shape.geometry)) {
          continue;
        }
        if (!boxes[i].Overlaps(BoundsOf(other_shape.geometry, world_from_b))) continue;
        ContactManifold manifold;
        if (!Collide(
                {&body.shapes[i].geometry, world_from_a, &other_shape.geometry, world_from_b, 0.0},
                nullptr, &manifold)) {
          continue;
        }
        for (int p = 0; p < manifold.point_count; ++p) {
          depth = std::max(depth, -manifold.points[p].separation);
        }
      }
    }
    if (depth > 0.0) overlaps.push_back({BodyId{index, other.generation}, depth});
  }
  std::sort(overlaps.begin(), overlaps.end(),
            [](const BodyOverlap& x, const BodyOverlap& y) { return x.depth > y.depth; });
  return overlaps;
}

}  // namespace rigid_body_sim::physics
