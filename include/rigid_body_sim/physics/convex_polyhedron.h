// Convex polyhedron with half-edge adjacency, as the narrow phase needs it.
#ifndef RIGID_BODY_SIM_PHYSICS_CONVEX_POLYHEDRON_H_
#define RIGID_BODY_SIM_PHYSICS_CONVEX_POLYHEDRON_H_

#include <array>
#include <vector>

#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// Half-edges come in twin pairs: half-edge 2k and 2k+1 are twins and form
// edge k, so twin(h) = h ^ 1. Each face is a convex polygon whose half-edges
// run counter-clockwise seen from outside.
struct ConvexPolyhedron {
  struct HalfEdge {
    int origin = -1;  // vertex the half-edge starts at
    int next = -1;    // next half-edge around the same face
    int face = -1;    // face to the left of the half-edge
  };
  struct Face {
    int first_half_edge = -1;
    Vec3 normal = Vec3::Zero();  // unit, outward
    double offset = 0.0;         // m; plane: normal . x = offset
  };

  std::vector<Vec3> vertices;  // m, shape frame, no duplicates
  std::vector<HalfEdge> half_edges;
  std::vector<Face> faces;
  std::vector<int> vertex_half_edge;  // one outgoing half-edge per vertex
  std::vector<Vec3> edge_directions;  // unit directions of edges, unique up to sign
  Vec3 centroid = Vec3::Zero();       // m, the volume centroid
  // The support vertices along +x, -x, +y, -y, +z, -z of the shape frame:
  // where a support query along a nearby direction starts its climb. Any
  // vertices are correct starts; these make the climb a few steps.
  std::array<int, 6> axis_support{};

  int EdgeCount() const { return static_cast<int>(half_edges.size() / 2); }
  static int Twin(int half_edge) { return half_edge ^ 1; }
  // Vertex indices of a face, counter-clockwise from outside.
  std::vector<int> FaceVertices(int face) const;
  // Index of the vertex furthest along `direction` (support mapping).
  int SupportVertex(const Vec3& direction) const;
  // The same, climbing from vertex `start` (any vertex is correct; one near
  // the answer is fast), or from the axis_support vertex nearest
  // `direction`. Where several vertices are furthest, any may be returned.
  int SupportVertexFrom(const Vec3& direction, int start) const;
  int SupportVertexNearAxis(const Vec3& direction) const;
  TriangleMesh Triangulate() const;
};

// Builds the half-edge structure from vertices and convex polygonal faces
// (each counter-clockwise from outside). Coplanar neighbouring faces are merged.
// Fails with a message when the faces do not form a closed 2-manifold or a
// face is degenerate.
Result<ConvexPolyhedron> MakeConvexPolyhedron(const std::vector<Vec3>& vertices,
                                              const std::vector<std::vector<int>>& faces);

// The builders below take validated parameters (asserted, not checked):
// finite positive sizes, segments >= 3, density > 0.
ConvexPolyhedron MakeBoxPolyhedron(const Vec3& size);  // full edge lengths, m, centred
// Prism with `segments` sides inscribed in the cylinder, axis z, centred.
ConvexPolyhedron MakeCylinderPolyhedron(double radius, double length, int segments);
// As the two above, for sizes from outside (asserts are off in Release):
// fail with a message naming the value instead, e.g. for a size that is not
// finite and positive, or proportions so extreme that a face degenerates.
Result<ConvexPolyhedron> TryMakeBoxPolyhedron(const Vec3& size);
Result<ConvexPolyhedron> TryMakeCylinderPolyhedron(double radius, double length, int segments);

MassProperties PolyhedronMassProperties(double density, const ConvexPolyhedron& polyhedron);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_CONVEX_POLYHEDRON_H_
