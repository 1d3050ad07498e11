// Axis-aligned bounding boxes in the world frame, the broad phase's bounds.
#ifndef RIGID_BODY_SIM_PHYSICS_GEOMETRY_AABB_H_
#define RIGID_BODY_SIM_PHYSICS_GEOMETRY_AABB_H_

#include <cassert>

#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// The box [min.x, max.x] x [min.y, max.y] x [min.z, max.z], world frame, m.
// Intervals are closed: boxes that share only a face, edge or corner overlap,
// because bodies resting exactly on each other must still reach the narrow
// phase.
struct Aabb {
  Vec3 min = Vec3::Zero();  // m, world
  Vec3 max = Vec3::Zero();  // m, world

  // Finite corners and min <= max on every axis (a zero extent is allowed).
  bool IsValid() const {
    return min.allFinite() && max.allFinite() && (min.array() <= max.array()).all();
  }

  // Overlap of the closed intervals on one axis (0 = x, 1 = y, 2 = z).
  bool OverlapsOnAxis(const Aabb& other, int axis) const {
    return min[axis] <= other.max[axis] && other.min[axis] <= max[axis];
  }

  // True when the intervals overlap on all three axes.
  bool Overlaps(const Aabb& other) const {
    return OverlapsOnAxis(other, 0) && OverlapsOnAxis(other, 1) && OverlapsOnAxis(other, 2);
  }

  // The smallest box containing both, e.g. the box swept from the start to
  // the end pose of a step.
  Aabb Union(const Aabb& other) const {
    return Aabb{min.cwiseMin(other.min), max.cwiseMax(other.max)};
  }

  // Grown by margin (m, >= 0) on every side, so that contacts are found
  // before the surfaces actually touch.
  Aabb Fattened(double margin) const {
    assert(margin >= 0.0);
    return Aabb{(min.array() - margin).matrix(), (max.array() + margin).matrix()};
  }
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_GEOMETRY_AABB_H_
