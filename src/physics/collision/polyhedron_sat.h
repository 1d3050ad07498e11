// The separating-axis test between convex polyhedra, shared by the query
// (QueryPolyhedronSeparation) and the collision driver (CollidePolyhedra).
#ifndef RIGID_BODY_SIM_PHYSICS_COLLISION_POLYHEDRON_SAT_H_
#define RIGID_BODY_SIM_PHYSICS_COLLISION_POLYHEDRON_SAT_H_

#include <vector>

#include "physics/collision/polyhedron_collision.h"

namespace rigid_body_sim::physics {

// The pair in the frame of A: B's vertices and face normals are mapped into
// it once per call.
struct PairInA {
  const ConvexPolyhedron* a = nullptr;
  const ConvexPolyhedron* b = nullptr;
  Pose world_from_a;
  Pose a_from_b;
  Mat3 b_from_a_matrix;                     // rotation, for the per-face queries
  double b_reach = 0.0;                     // m, the largest |vertex| of B in B's frame
  std::vector<Vec3>* b_vertices = nullptr;  // m, frame A
  std::vector<Vec3>* b_normals = nullptr;   // unit, frame A
};

// B's vertices and face normals moved into A's frame, in per-thread scratch
// that the next call on the thread overwrites.
PairInA MakePairInA(const PolyhedronPair& pair);

// The separation along a cached face witness straight from the two poses;
// -infinity for any other witness.
double FaceWitnessSeparation(const PolyhedronPair& pair, const SeparatingWitness& witness);

// The separation along a cached edge-pair witness, with its axis, and
// whether the two edges still form a face of the Minkowski difference;
// -infinity for a witness that does not fit the pair.
double EdgeWitnessSeparation(const PairInA& frame, const SeparatingWitness& witness,
                             Vec3* normal_world, bool* still_minkowski_face);

// The distance between edge `edge_a` of A and edge `edge_b` of B, as
// segments.
double EdgePairDistance(const PairInA& frame, int edge_a, int edge_b);

// Every candidate axis, stopping once one separates by more than `early_out`.
SatResult RunSat(const PairInA& frame, double early_out);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_COLLISION_POLYHEDRON_SAT_H_
