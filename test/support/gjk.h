// Distance between two convex point sets by GJK, independent of the
// separating-axis code: the reference the narrow-phase tests compare the
// separating-axis test with. The simulation itself does not call it.
#ifndef RIGID_BODY_SIM_TEST_SUPPORT_GJK_H_
#define RIGID_BODY_SIM_TEST_SUPPORT_GJK_H_

#include <vector>

#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// Each set is the convex hull of its points, given in its own frame.
struct GjkInput {
  const std::vector<Vec3>* points_a = nullptr;  // m, frame a, non-empty
  Pose world_from_a = Pose::Identity();
  const std::vector<Vec3>* points_b = nullptr;  // m, frame b, non-empty
  Pose world_from_b = Pose::Identity();
};

struct GjkResult {
  double distance = 0.0;  // m; 0 when the hulls touch or overlap
  // True when the origin was found inside (or within rounding of) the
  // Minkowski difference: the hulls touch or interpenetrate. The closest
  // points are then not meaningful.
  bool overlapping = false;
  Vec3 point_a_world = Vec3::Zero();  // m, closest point on hull a
  Vec3 point_b_world = Vec3::Zero();  // m, closest point on hull b
  // Number of support points spanning the closest feature of A - B when
  // separated: 1 vertex/vertex, 2 an edge of A - B (vertex/edge or parallel
  // edges), 3 a face of A - B (vertex/face or edge/edge).
  int simplex_count = 0;
  int iterations = 0;
};

// Gilbert, Johnson and Keerthi (1988): the closest point v of the Minkowski
// difference A - B to the origin, found by growing a simplex of support
// points w = s_A(-v) - s_B(v) and keeping the sub-simplex whose Voronoi
// region holds the origin. Stops when the lower bound v.w / |v| meets |v|.
GjkResult GjkDistance(const GjkInput& input);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_TEST_SUPPORT_GJK_H_
