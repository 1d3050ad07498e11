// Stage 2 of World::Step: a contact manifold for every pair of shapes of the
// candidate body pairs, each starting from its cached separating witness.
#include <algorithm>
#include <variant>

#include "rigid_body_sim/physics/narrow_phase.h"
#include "rigid_body_sim/physics/shape_bounds.h"
#include "rigid_body_sim/physics/world.h"

namespace rigid_body_sim::physics {

void World::UpdateNarrowPhase(double dt) {
  ++step_count_;
  for (const ProxyPair& pair : broad_phase_.Pairs()) {
    CollideBodies(static_cast<std::uint32_t>(pair.first), static_cast<std::uint32_t>(pair.second),
                  dt);
  }
  for (const std::uint32_t plane : half_space_bodies_) {
    for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
      const Body& body = bodies_[i];
      if (body.in_use && !body.is_static && body.awake && !body.shapes.empty()) {
        CollideBodies(i, plane, dt);
      }
    }
  }
}

// Body A is the moving one when only one moves, so normals point from the
// static or sleeping body B into A. Contact points are reported up to the
// margin plus the distance the two bodies can close in one step.
void World::CollideBodies(std::uint32_t body_a, std::uint32_t body_b, double dt) {
  if (bodies_[body_a].is_static || !bodies_[body_a].awake) std::swap(body_a, body_b);
  const Body& a = bodies_[body_a];
  const Body& b = bodies_[body_b];
  const double closing_speed = (a.linear_velocity - b.linear_velocity).norm() +
                               a.angular_velocity.norm() * a.bounding_radius +
                               b.angular_velocity.norm() * b.bounding_radius;
  const double contact_distance =
      settings_.contact_margin + dt * closing_speed + 0.5 * dt * dt * settings_.gravity.norm();
  const Pose world_from_a = a.WorldFromBody();
  const Pose world_from_b = b.WorldFromBody();
  const bool compound = a.shapes.size() > 1 || b.shapes.size() > 1;
  for (std::size_t i = 0; i < a.shapes.size(); ++i) {
    const ShapeDef& shape_a = a.shapes[i];
    const Pose world_from_shape_a = world_from_a * shape_a.body_from_shape;
    for (std::size_t k = 0; k < b.shapes.size(); ++k) {
      const ShapeDef& shape_b = b.shapes[k];
      const Pose world_from_shape_b = world_from_b * shape_b.body_from_shape;
      // Compound bodies: skip shape pairs whose own boxes are apart.
      if (compound && !std::holds_alternative<HalfSpace>(shape_b.geometry) &&
          !ShapeAabb(shape_a.geometry, world_from_shape_a)
               .Fattened(contact_distance)
               .Overlaps(ShapeAabb(shape_b.geometry, world_from_shape_b))) {
        continue;
      }
      ShapePairContact& entry = contact_cache_.Touch(body_a, static_cast<std::uint16_t>(i), body_b,
                                                     static_cast<std::uint16_t>(k), step_count_);
      CollideInput input;
      input.a = &shape_a.geometry;
      input.world_from_a = world_from_shape_a;
      input.b = &shape_b.geometry;
      input.world_from_b = world_from_shape_b;
      input.contact_distance = contact_distance;
      entry.contact_distance = contact_distance;
      Collide(input, &entry.witness, &entry.manifold);
    }
  }
}

}  // namespace rigid_body_sim::physics
