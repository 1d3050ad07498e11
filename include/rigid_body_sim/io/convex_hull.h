// Convex hulls of point sets (reentrant qhull), as narrow-phase polyhedra.
#ifndef RIGID_BODY_SIM_IO_CONVEX_HULL_H_
#define RIGID_BODY_SIM_IO_CONVEX_HULL_H_

#include <vector>

#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

struct HullOptions {
  // Count, >= 4. A hull with more vertices is simplified: it keeps the hull
  // vertices that are extreme (support points) in a spherical Fibonacci
  // lattice of directions, with as many directions as fit under the limit.
  // The simplified hull is inside the full one and touches it in every
  // lattice direction. For a sphere with n kept vertices the relative volume
  // loss is close to that of an inscribed polytope with n evenly spread
  // vertices: 2n equilateral faces of circumradius rho, rho^2 =
  // 8 pi / (3 sqrt(3) n), each missing a cap of mean depth 3 rho^2 / 8, so
  // a loss of 3 * 9 rho^2 / 8 = sqrt(3) pi / n (2.1 % at n = 256).
  int max_vertices = 256;
  // Dimensionless, relative to the bounding-box diagonal: points closer than
  // this to a common line or plane are refused as degenerate.
  double degenerate_tolerance = 1e-9;
};

// Convex hull of `points` (m) as a polyhedron with merged coplanar faces,
// half-edge adjacency, face planes and unique edge directions. Without
// simplification every hull vertex is one of the input points. Fails with a
// message for fewer than 4 points, non-finite coordinates, points that all lie
// on a line or a plane, or invalid options.
physics::Result<physics::ConvexPolyhedron> ComputeConvexHull(
    const std::vector<physics::Vec3>& points, const HullOptions& options = {});

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_CONVEX_HULL_H_
