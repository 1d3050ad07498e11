// Contact manifolds between convex polyhedra from their defining feature:
// a face clipped against a face, or an edge against an edge.
#ifndef RIGID_BODY_SIM_PHYSICS_COLLISION_POLYHEDRON_MANIFOLD_H_
#define RIGID_BODY_SIM_PHYSICS_COLLISION_POLYHEDRON_MANIFOLD_H_

#include "physics/collision/polyhedron_collision.h"

namespace rigid_body_sim::physics {

struct FaceContactInput {
  const ConvexPolyhedron* reference = nullptr;
  Pose world_from_reference;
  int reference_face = -1;
  const ConvexPolyhedron* incident = nullptr;
  Pose world_from_incident;
  bool reference_is_a = true;
  double contact_distance = 0.0;  // m
};

// Face contact (Sutherland and Hodgman 1974 clipping): the incident face is
// the face of the other shape most anti-parallel to the reference normal n;
// its polygon is clipped by the side planes of the reference face (normal
// m_k = (v_k+1 - v_k) x n, outward since faces run counter-clockwise).
// Points with s = n.p - d < contact distance are kept, moved to the middle
// between the surfaces (p - n s / 2). Each point keeps the features that
// produced it, so its id is the same whenever the configuration is.
bool BuildFaceContact(const FaceContactInput& input, ContactManifold* manifold);

// Closest points of segments p0 + s d1 and q0 + t d2, s, t in [0, 1]:
// minimise |p0 + s d1 - q0 - t d2|^2; the unconstrained s is clamped, t
// follows from s and is clamped, and s is recomputed from the clamped t
// (Ericson, "Real-Time Collision Detection", 2005, section 5.1.9). Both
// segments must have a positive length.
void ClosestPointsOfSegments(const Vec3& p0, const Vec3& d1, const Vec3& q0, const Vec3& d2,
                             Vec3* on_p, Vec3* on_q);

// Baraff's edge/edge contact: one point midway between the closest points
// of the two edges.
bool BuildEdgeContact(const PolyhedronPair& pair, int edge_a, int edge_b, double separation,
                      const Vec3& normal_world, ContactManifold* manifold);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_COLLISION_POLYHEDRON_MANIFOLD_H_
