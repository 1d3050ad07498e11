// Structural checks of convex polyhedra shared by the io tests.
#ifndef RIGID_BODY_SIM_TEST_IO_POLYHEDRON_CHECKS_H_
#define RIGID_BODY_SIM_TEST_IO_POLYHEDRON_CHECKS_H_

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

#include "rigid_body_sim/physics/convex_polyhedron.h"

namespace rigid_body_sim::io::testing {

// Half-edge invariants, Euler's formula V - E + F = 2, distinct vertices,
// planar convex faces, and every vertex on or below every face plane.
inline void ExpectValidConvexPolyhedron(const physics::ConvexPolyhedron& polyhedron,
                                        double tolerance) {
  using physics::ConvexPolyhedron;
  const int vertex_count = static_cast<int>(polyhedron.vertices.size());
  const int face_count = static_cast<int>(polyhedron.faces.size());
  EXPECT_EQ(vertex_count - polyhedron.EdgeCount() + face_count, 2);
  ASSERT_EQ(polyhedron.vertex_half_edge.size(), polyhedron.vertices.size());
  for (int h = 0; h < static_cast<int>(polyhedron.half_edges.size()); ++h) {
    const ConvexPolyhedron::HalfEdge& half_edge = polyhedron.half_edges[h];
    const ConvexPolyhedron::HalfEdge& next = polyhedron.half_edges[half_edge.next];
    // The next half-edge starts where the twin starts (where this one ends).
    EXPECT_EQ(next.origin, polyhedron.half_edges[ConvexPolyhedron::Twin(h)].origin);
    EXPECT_EQ(next.face, half_edge.face);
    EXPECT_NE(half_edge.face, polyhedron.half_edges[ConvexPolyhedron::Twin(h)].face);
  }
  std::set<std::array<double, 3>> distinct;
  for (int v = 0; v < vertex_count; ++v) {
    EXPECT_EQ(polyhedron.half_edges[polyhedron.vertex_half_edge[v]].origin, v);
    const physics::Vec3& p = polyhedron.vertices[v];
    distinct.insert({p.x(), p.y(), p.z()});
  }
  EXPECT_EQ(static_cast<int>(distinct.size()), vertex_count);
  for (int f = 0; f < face_count; ++f) {
    const ConvexPolyhedron::Face& face = polyhedron.faces[f];
    EXPECT_NEAR(face.normal.norm(), 1.0, 1e-12);
    const std::vector<int> loop = polyhedron.FaceVertices(f);
    EXPECT_GE(loop.size(), 3u);
    for (int v : loop) {
      EXPECT_NEAR(face.normal.dot(polyhedron.vertices[v]), face.offset, tolerance);
    }
    double highest = -std::numeric_limits<double>::infinity();
    for (const physics::Vec3& vertex : polyhedron.vertices) {
      highest = std::max(highest, face.normal.dot(vertex) - face.offset);
    }
    EXPECT_LE(highest, tolerance) << "face " << f;
  }
}

}  // namespace rigid_body_sim::io::testing

#endif  // RIGID_BODY_SIM_TEST_IO_POLYHEDRON_CHECKS_H_
