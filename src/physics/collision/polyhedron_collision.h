// Separating-axis test and contact manifolds between convex polyhedra.
#ifndef RIGID_BODY_SIM_PHYSICS_COLLISION_POLYHEDRON_COLLISION_H_
#define RIGID_BODY_SIM_PHYSICS_COLLISION_POLYHEDRON_COLLISION_H_

#include <limits>

#include "physics/contact/contact_manifold.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// What one narrow-phase call did, for tests and statistics.
struct CollideStats {
  // The cached witness still separated the shapes by more than the contact
  // distance, so the full test was skipped.
  bool witness_early_out = false;
  // The cached feature was kept as the defining feature.
  bool witness_kept = false;
  // ...without running the full test: the bound kept when it last ran
  // proves it would keep the feature (SeparatingWitness::distance_bound).
  bool test_skipped = false;
  // m; with no contact points, the gap along an axis that separates the
  // shapes: a lower bound on their distance (-infinity when not known).
  double gap = -std::numeric_limits<double>::infinity();
};

struct FaceQuery {
  int face = -1;                                                 // face index, -1 if none
  double separation = -std::numeric_limits<double>::infinity();  // m
};

struct EdgeQuery {
  int edge_a = -1;  // edge index of A (half-edges 2 edge_a, 2 edge_a + 1), -1 if none
  int edge_b = -1;  // edge index of B
  double separation = -std::numeric_limits<double>::infinity();  // m
  Vec3 normal_world = Vec3::UnitZ();                             // unit, from B to A
};

// The separating-axis test over every candidate axis, without early exit.
// The separation along a unit axis n (from B to A) is
//   s(n) = min_{x in A} n.x - max_{y in B} n.y,
// positive when the plane n.x = const separates the shapes. The maximum of s
// over face normals of A, face normals of B and the edge-pair crosses that
// form faces of the Minkowski difference is the distance along the best axis
// when positive, and minus the penetration depth when not.
struct SatResult {
  FaceQuery face_a;  // best face of A: its outward normal points from A to B
  FaceQuery face_b;  // best face of B
  EdgeQuery edges;   // best edge pair among those that may beat the faces (edge_a -1: none)
  double separation = -std::numeric_limits<double>::infinity();  // m, max of the three
  Vec3 normal_world = Vec3::UnitZ();  // unit, from B to A, the axis of `separation`
  SeparatingWitness witness;          // the feature of `separation`
};

SatResult QueryPolyhedronSeparation(const ConvexPolyhedron& a, const Pose& world_from_a,
                                    const ConvexPolyhedron& b, const Pose& world_from_b);

struct PolyhedronPair {
  const ConvexPolyhedron* a = nullptr;
  Pose world_from_a = Pose::Identity();
  const ConvexPolyhedron* b = nullptr;
  Pose world_from_b = Pose::Identity();
  double contact_distance = 0.0;  // m: points with separation below this are contacts
};

// Polyhedron against polyhedron: cached witness first, then the full
// separating-axis test with early exit, then the manifold of the defining
// feature. Returns true when the manifold has points; `witness` may be null,
// `stats` may be null.
bool CollidePolyhedra(const PolyhedronPair& pair, SeparatingWitness* witness,
                      ContactManifold* manifold, CollideStats* stats);

// Reduces `count` points sharing `normal_world` to at most four: the deepest
// point, the point furthest from it, the point that maximises the triangle
// area, then the point that adds the most area to the quad. Fewer than five
// points are kept as they are. Writes the points to `manifold->points` and
// sets `manifold->point_count`.
void ReduceContactPoints(const ContactPoint* points, int count, const Vec3& normal_world,
                         ContactManifold* manifold);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_COLLISION_POLYHEDRON_COLLISION_H_
