#include "rigid_body_sim/physics/convex_polyhedron.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace rigid_body_sim::physics {
namespace {

// Up to this many vertices a linear scan beats hill climbing.
constexpr int kLinearSupportLimit = 32;

// Support mapping argmax_v d.v. On a convex polytope a vertex none of whose
// neighbours is further along d is a global maximum (the linear function
// has no other local maxima on the vertex graph), so steepest ascent over
// the adjacency from vertex_half_edge finds it; each step strictly increases
// d.v, so it terminates. Small polyhedra use a linear scan.
int ClimbToSupport(const ConvexPolyhedron& p, const Vec3& direction, int start) {
  assert(!p.vertices.empty());
  const int vertex_count = static_cast<int>(p.vertices.size());
  if (vertex_count <= kLinearSupportLimit || p.half_edges.empty()) {
    int best = 0;
    double best_distance = p.vertices[0].dot(direction);
    for (int v = 1; v < vertex_count; ++v) {
      const double distance = p.vertices[v].dot(direction);
      if (distance > best_distance) {
        best = v;
        best_distance = distance;
      }
    }
    return best;
  }
  int best = start >= 0 && start < vertex_count ? start : 0;
  double best_distance = p.vertices[best].dot(direction);
  for (;;) {
    int step_to = best;
    double step_distance = best_distance;
    // Outgoing half-edges of a vertex: h, next(twin(h)), ...
    const int first = p.vertex_half_edge[best];
    int h = first;
    do {
      const int neighbour = p.half_edges[ConvexPolyhedron::Twin(h)].origin;
      const double distance = p.vertices[neighbour].dot(direction);
      if (distance > step_distance) {
        step_to = neighbour;
        step_distance = distance;
      }
      h = p.half_edges[ConvexPolyhedron::Twin(h)].next;
    } while (h != first);
    if (step_to == best) return best;
    best = step_to;
    best_distance = step_distance;
  }
}

}  // namespace

std::vector<int> ConvexPolyhedron::FaceVertices(int face) const {
  assert(face >= 0 && face < static_cast<int>(faces.size()));
  std::vector<int> result;
  const int first = faces[face].first_half_edge;
  int h = first;
  do {
    result.push_back(half_edges[h].origin);
    h = half_edges[h].next;
  } while (h != first);
  return result;
}

int ConvexPolyhedron::SupportVertex(const Vec3& direction) const {
  return ClimbToSupport(*this, direction, 0);
}

int ConvexPolyhedron::SupportVertexFrom(const Vec3& direction, int start) const {
  return ClimbToSupport(*this, direction, start);
}

int ConvexPolyhedron::SupportVertexNearAxis(const Vec3& direction) const {
  int axis = 0;
  direction.cwiseAbs().maxCoeff(&axis);
  return ClimbToSupport(*this, direction, axis_support[2 * axis + (direction[axis] < 0.0 ? 1 : 0)]);
}

// Fan triangulation (v0, vi, vi+1) of each convex, counter-clockwise face
// keeps the outward orientation.
TriangleMesh ConvexPolyhedron::Triangulate() const {
  TriangleMesh mesh;
  mesh.vertices = vertices;
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
    const std::vector<int> loop = FaceVertices(f);
    for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
      mesh.triangles.emplace_back(loop[0], loop[i], loop[i + 1]);
    }
  }
  return mesh;
}

// Vertex i has coordinate bit k set when it lies on the + side of axis k.
// The face normal to axis a uses the cyclic axes b = a+1, c = a+2; the
// corner order (0,0), (1,0), (1,1), (0,1) in (b, c) runs counter-clockwise
// seen from +a since e_b x e_c = e_a, and reversed for the - face.
Result<ConvexPolyhedron> TryMakeBoxPolyhedron(const Vec3& size) {
  if (!size.allFinite() || !(size.array() > 0.0).all()) {
    return Result<ConvexPolyhedron>::Error("box size (" + FormatNumber(size.x()) + ", " +
                                           FormatNumber(size.y()) + ", " + FormatNumber(size.z()) +
                                           ") m must be finite and positive");
  }
  std::vector<Vec3> vertices(8);
  for (int i = 0; i < 8; ++i) {
    for (int k = 0; k < 3; ++k) vertices[i][k] = ((i >> k) & 1 ? 0.5 : -0.5) * size[k];
  }
  std::vector<std::vector<int>> faces;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3;
    const int c = (a + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      const int base = side << a;
      std::vector<int> face = {base, base | (1 << b), base | (1 << b) | (1 << c), base | (1 << c)};
      if (side == 0) std::reverse(face.begin(), face.end());
      faces.push_back(face);
    }
  }
  return MakeConvexPolyhedron(vertices, faces);
}

ConvexPolyhedron MakeBoxPolyhedron(const Vec3& size) {
  assert(size.allFinite() && (size.array() > 0.0).all());
  Result<ConvexPolyhedron> box = TryMakeBoxPolyhedron(size);
  assert(box.ok());
  return std::move(box).value();
}

// Bottom ring i at z = -l/2, top ring segments + i at z = +l/2, angle
// 2 pi i / segments. Side quad i (b_i, b_i+1, t_i+1, t_i) is counter-clockwise
// from outside; the top cap runs with increasing angle, the bottom against.
Result<ConvexPolyhedron> TryMakeCylinderPolyhedron(double radius, double length, int segments) {
  if (!std::isfinite(radius) || !(radius > 0.0) || !std::isfinite(length) || !(length > 0.0)) {
    return Result<ConvexPolyhedron>::Error("cylinder radius " + FormatNumber(radius) +
                                           " m and length " + FormatNumber(length) +
                                           " m must be finite and positive");
  }
  if (segments < 3) {
    return Result<ConvexPolyhedron>::Error("cylinder segments " + std::to_string(segments) +
                                           " must be >= 3");
  }
  std::vector<Vec3> vertices(2 * segments);
  for (int i = 0; i < segments; ++i) {
    const double angle = 2.0 * kPi * i / segments;
    const double x = radius * std::cos(angle);
    const double y = radius * std::sin(angle);
    vertices[i] = Vec3(x, y, -0.5 * length);
    vertices[segments + i] = Vec3(x, y, 0.5 * length);
  }
  std::vector<std::vector<int>> faces;
  std::vector<int> top;
  std::vector<int> bottom;
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    faces.push_back({i, j, segments + j, segments + i});
    top.push_back(segments + i);
    bottom.push_back(segments - 1 - i);
  }
  faces.push_back(top);
  faces.push_back(bottom);
  return MakeConvexPolyhedron(vertices, faces);
}

ConvexPolyhedron MakeCylinderPolyhedron(double radius, double length, int segments) {
  assert(std::isfinite(radius) && radius > 0.0);
  assert(std::isfinite(length) && length > 0.0);
  assert(segments >= 3);
  Result<ConvexPolyhedron> cylinder = TryMakeCylinderPolyhedron(radius, length, segments);
  assert(cylinder.ok());
  return std::move(cylinder).value();
}

MassProperties PolyhedronMassProperties(double density, const ConvexPolyhedron& polyhedron) {
  assert(std::isfinite(density) && density > 0.0);
  const Result<MassProperties> result =
      TriangleMeshMassProperties(density, polyhedron.Triangulate());
  assert(result.ok());
  return result.value();
}

}  // namespace rigid_body_sim::physics
