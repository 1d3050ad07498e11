// The separating-axis test between convex polyhedra: face normals of both,
// and the edge pairs that form faces of the Minkowski difference
// (Gregorius, "The Separating Axis Test between Convex Polyhedra", GDC 2013).
#include "physics/collision/polyhedron_sat.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

#include "physics/collision/polyhedron_manifold.h"

namespace rigid_body_sim::physics {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Edge pairs with |e_a x e_b| below kParallelSine |e_a| |e_b| are parallel:
// their Gauss-map arcs lie on one great circle, they form no face of the
// Minkowski difference, and the face normals at the arc ends cover them.
// Nearly parallel pairs skipped by this bound form Minkowski faces narrower
// than kParallelSine times the edge length, so the best separation moves by
// less than that.
constexpr double kParallelSine = 1e-8;

// Face f of A with outward normal n and plane n.x = d: B's deepest point
// along -n is its support vertex in -n, and s = n.v - d.
double FaceOfASeparation(const PairInA& frame, int face) {
  const ConvexPolyhedron::Face& plane = frame.a->faces[face];
  const int support = frame.b->SupportVertex(-Multiply(frame.b_from_a_matrix, plane.normal));
  return plane.normal.dot((*frame.b_vertices)[support]) - plane.offset;
}

// Face f of B, moved into frame A: n' = R n, d' = d + n'.t.
double FaceOfBSeparation(const PairInA& frame, int face) {
  const Vec3& normal = (*frame.b_normals)[face];
  const double offset = frame.b->faces[face].offset + normal.dot(frame.a_from_b.translation);
  return normal.dot(frame.a->vertices[frame.a->SupportVertex(-normal)]) - offset;
}

// Best face of A (max over faces of the separation); stops early once a
// face separates by more than `early_out`.
FaceQuery QueryFacesOfA(const PairInA& frame, double early_out) {
  FaceQuery query;
  for (int f = 0; f < static_cast<int>(frame.a->faces.size()); ++f) {
    const double separation = FaceOfASeparation(frame, f);
    if (separation > query.separation) {
      query = {f, separation};
      if (separation > early_out) break;
    }
  }
  return query;
}

FaceQuery QueryFacesOfB(const PairInA& frame, double early_out) {
  FaceQuery query;
  for (int f = 0; f < static_cast<int>(frame.b->faces.size()); ++f) {
    const double separation = FaceOfBSeparation(frame, f);
    if (separation > query.separation) {
      query = {f, separation};
      if (separation > early_out) break;
    }
  }
  return query;
}

// Gregorius, GDC 2013, Gauss-map pruning: edges a (faces with normals na, nb)
// and b (faces nc, nd) build a face of the Minkowski difference A - B iff the
// arc na-nb and the arc -nc -> -nd cross on the unit sphere. With
// bxa = nb x na and dxc = nd x nc the arcs cross iff -nc and -nd lie on
// opposite sides of the plane of arc a, na and nb on opposite sides of the
// plane of arc b, and the crossing is the same point, not its antipode:
//   (-nc.bxa)(-nd.bxa) < 0,  (na.dxc)(nb.dxc) < 0,  (-nc.bxa)(nb.dxc) > 0.
// The last two tests, given the first's products cba = -nc.bxa and
// dba = -nd.bxa, which QueryEdges takes once per edge of A and face of B.
bool ArcsCross(double cba, double dba, const Vec3& na, const Vec3& nb, const Vec3& dxc) {
  if (!(cba * dba < 0.0)) return false;
  const double adc = na.dot(dxc);
  const double bdc = nb.dot(dxc);
  return adc * bdc < 0.0 && cba * bdc > 0.0;
}

bool IsMinkowskiFace(const Vec3& na, const Vec3& nb, const Vec3& bxa, const Vec3& nc,
                     const Vec3& nd, const Vec3& dxc) {
  // Most pairs fail the first test; the rest is computed only when needed.
  return ArcsCross(-nc.dot(bxa), -nd.dot(bxa), na, nb, dxc);
}

struct EdgeInA {
  Vec3 start;      // m, frame A
  Vec3 direction;  // end - start
  Vec3 normal_left;
  Vec3 normal_right;
};

EdgeInA EdgeOfA(const PairInA& frame, int edge) {
  const ConvexPolyhedron& a = *frame.a;
  const ConvexPolyhedron::HalfEdge& h = a.half_edges[2 * edge];
  const ConvexPolyhedron::HalfEdge& t = a.half_edges[2 * edge + 1];
  return {a.vertices[h.origin], a.vertices[t.origin] - a.vertices[h.origin], a.faces[h.face].normal,
          a.faces[t.face].normal};
}

EdgeInA EdgeOfB(const PairInA& frame, int edge) {
  const ConvexPolyhedron& b = *frame.b;
  const ConvexPolyhedron::HalfEdge& h = b.half_edges[2 * edge];
  const ConvexPolyhedron::HalfEdge& t = b.half_edges[2 * edge + 1];
  const Vec3& start = (*frame.b_vertices)[h.origin];
  return {start, (*frame.b_vertices)[t.origin] - start, (*frame.b_normals)[h.face],
          (*frame.b_normals)[t.face]};
}

// Unit axis e_a x e_b, turned to point out of A at edge a (away from A's
// centroid, which is interior), or false for parallel edges.
bool EdgeAxis(const PairInA& frame, const EdgeInA& edge_a, const EdgeInA& edge_b, Vec3* axis) {
  const Vec3 cross = edge_a.direction.cross(edge_b.direction);
  const double length = cross.norm();
  if (!(length > kParallelSine * edge_a.direction.norm() * edge_b.direction.norm())) return false;
  *axis = cross / length;
  if (axis->dot(edge_a.start - frame.a->centroid) < 0.0) *axis = -*axis;
  return true;
}

// Whether the pair's axis e_a x e_b can separate by more than `best`: the
// separation along it is c.d / |c| with c = e_a x e_b (turned out of A) and
// d = p_b - p_a, so with both sides squared no root is taken for the pairs
// that lose by far, most of them once a face has touched. A pair is passed
// on unless it loses by more than a relative 1e-9, so that EdgeAxis and the
// separation, computed as before, decide every close call.
bool MayBeatSeparation(const PairInA& frame, const EdgeInA& edge_a, const EdgeInA& edge_b,
                       double best) {
  const Vec3 cross = edge_a.direction.cross(edge_b.direction);
  const double outward = cross.dot(edge_a.start - frame.a->centroid) < 0.0 ? -1.0 : 1.0;
  const double projection = outward * cross.dot(edge_b.start - edge_a.start);
  if (!(projection < 0.0) || !(best > -kInfinity)) return true;
  // Both negative, s = projection / |c|: s < best iff projection^2 > best^2 |c|^2.
  return !(best >= 0.0 ||
           projection * projection > (1.0 + 1e-9) * best * best * cross.squaredNorm());
}

// Best edge pair over the Minkowski-face pairs. On such a pair the edges are
// the supports of A along the axis and of B against it, so the separation is
// axis.(p_b - p_a) with any points on the two edges. The first Gauss-map
// test (IsMinkowskiFace) reads each of B's face normals against an edge of
// A's arc, so those products are taken once per edge of A, face by face.
EdgeQuery QueryEdges(const PairInA& frame, double early_out, double best_face) {
  thread_local std::vector<EdgeInA> b_edges;
  thread_local std::vector<Vec3> b_arc_normals;
  thread_local std::vector<double> b_face_sides;
  const ConvexPolyhedron& b = *frame.b;
  const int b_edge_count = b.EdgeCount();
  b_edges.resize(b_edge_count);
  b_arc_normals.resize(b_edge_count);
  b_face_sides.resize(b.faces.size());
  for (int e = 0; e < b_edge_count; ++e) {
    b_edges[e] = EdgeOfB(frame, e);
    b_arc_normals[e] = b_edges[e].normal_right.cross(b_edges[e].normal_left);
  }
  EdgeQuery query;
  Vec3 best_axis = Vec3::UnitZ();
  for (int ea = 0; ea < frame.a->EdgeCount(); ++ea) {
    const EdgeInA edge_a = EdgeOfA(frame, ea);
    const Vec3 bxa = edge_a.normal_right.cross(edge_a.normal_left);
    for (std::size_t f = 0; f < b.faces.size(); ++f) {
      b_face_sides[f] = -(*frame.b_normals)[f].dot(bxa);
    }
    for (int eb = 0; eb < b_edge_count; ++eb) {
      const EdgeInA& edge_b = b_edges[eb];
      // -n_c . (n_b x n_a) and -n_d . (n_b x n_a) of IsMinkowskiFace.
      const double cba = b_face_sides[b.half_edges[2 * eb].face];
      const double dba = b_face_sides[b.half_edges[2 * eb + 1].face];
      if (!ArcsCross(cba, dba, edge_a.normal_left, edge_a.normal_right, b_arc_normals[eb])) {
        continue;
      }
      if (!MayBeatSeparation(frame, edge_a, edge_b, std::max(best_face, query.separation))) {
        continue;
      }
      Vec3 axis;
      if (!EdgeAxis(frame, edge_a, edge_b, &axis)) continue;
      const double separation = axis.dot(edge_b.start - edge_a.start);
      if (separation > query.separation) {
        query.edge_a = ea;
        query.edge_b = eb;
        query.separation = separation;
        best_axis = axis;
        if (separation > early_out) break;
      }
    }
    if (query.separation > early_out) break;
  }
  query.normal_world = frame.world_from_a.rotation * (-best_axis);
  return query;
}

}  // namespace

PairInA MakePairInA(const PolyhedronPair& pair) {
  thread_local std::vector<Vec3> b_vertices;
  thread_local std::vector<Vec3> b_normals;
  PairInA frame;
  frame.a = pair.a;
  frame.b = pair.b;
  frame.world_from_a = pair.world_from_a;
  frame.a_from_b = pair.world_from_a.Inverse() * pair.world_from_b;
  const Mat3 rotation = frame.a_from_b.rotation.toRotationMatrix();
  frame.b_from_a_matrix = rotation.transpose();
  b_vertices.resize(pair.b->vertices.size());
  double b_reach_squared = 0.0;
  for (std::size_t i = 0; i < b_vertices.size(); ++i) {
    b_vertices[i] = Multiply(rotation, pair.b->vertices[i]) + frame.a_from_b.translation;
    b_reach_squared = std::max(b_reach_squared, pair.b->vertices[i].squaredNorm());
  }
  frame.b_reach = std::sqrt(b_reach_squared);
  b_normals.resize(pair.b->faces.size());
  for (std::size_t i = 0; i < b_normals.size(); ++i) {
    b_normals[i] = Multiply(rotation, pair.b->faces[i].normal);
  }
  frame.b_vertices = &b_vertices;
  frame.b_normals = &b_normals;
  return frame;
}

double EdgePairDistance(const PairInA& frame, int edge_a, int edge_b) {
  const EdgeInA a = EdgeOfA(frame, edge_a);
  const EdgeInA b = EdgeOfB(frame, edge_b);
  Vec3 on_a;
  Vec3 on_b;
  ClosestPointsOfSegments(a.start, a.direction, b.start, b.direction, &on_a, &on_b);
  return (on_a - on_b).norm();
}

// Separation along a cached edge-pair witness (Baraff's coherence: the
// plane that separated last step is tried first). It uses the support
// functions, since after motion the two edges need no longer be the
// supports. Returns -infinity for a witness that does not fit the pair;
// face witnesses are FaceWitnessSeparation's.
double EdgeWitnessSeparation(const PairInA& frame, const SeparatingWitness& witness,
                             Vec3* edge_normal_world, bool* still_minkowski_face) {
  *still_minkowski_face = false;
  switch (witness.type) {
    case SeparatingWitness::Type::kEdges: {
      if (witness.index_a < 0 || witness.index_a >= frame.a->EdgeCount() || witness.index_b < 0 ||
          witness.index_b >= frame.b->EdgeCount()) {
        break;
      }
      const EdgeInA edge_a = EdgeOfA(frame, witness.index_a);
      const EdgeInA edge_b = EdgeOfB(frame, witness.index_b);
      Vec3 axis;
      if (!EdgeAxis(frame, edge_a, edge_b, &axis)) break;
      *still_minkowski_face = IsMinkowskiFace(
          edge_a.normal_left, edge_a.normal_right, edge_a.normal_right.cross(edge_a.normal_left),
          edge_b.normal_left, edge_b.normal_right, edge_b.normal_right.cross(edge_b.normal_left));
      *edge_normal_world = frame.world_from_a.rotation * (-axis);
      const Vec3& support_b =
          (*frame.b_vertices)[frame.b->SupportVertex(-Multiply(frame.b_from_a_matrix, axis))];
      const Vec3& support_a = frame.a->vertices[frame.a->SupportVertex(axis)];
      return axis.dot(support_b - support_a);
    }
    case SeparatingWitness::Type::kNone:
    case SeparatingWitness::Type::kFaceA:
    case SeparatingWitness::Type::kFaceB:
      break;
  }
  return -kInfinity;
}

// The separation along a cached face witness straight from the two poses,
// before the whole of B is moved into A's frame: the face's plane moved
// into the other shape's frame and that shape's support vertex against it
// (the same s as FaceOfASeparation / FaceOfBSeparation). A pair that stays
// apart, most of the broad phase's pairs, costs two rotations and one
// support query. -infinity for any other witness.
double FaceWitnessSeparation(const PolyhedronPair& pair, const SeparatingWitness& witness) {
  const bool face_of_a = witness.type == SeparatingWitness::Type::kFaceA;
  if (!face_of_a && witness.type != SeparatingWitness::Type::kFaceB) return -kInfinity;
  const ConvexPolyhedron& owner = face_of_a ? *pair.a : *pair.b;
  const ConvexPolyhedron& other = face_of_a ? *pair.b : *pair.a;
  const int face = face_of_a ? witness.index_a : witness.index_b;
  if (face < 0 || face >= static_cast<int>(owner.faces.size())) return -kInfinity;
  const Pose& world_from_owner = face_of_a ? pair.world_from_a : pair.world_from_b;
  const Pose& world_from_other = face_of_a ? pair.world_from_b : pair.world_from_a;
  const Pose other_from_owner = world_from_other.Inverse() * world_from_owner;
  const ConvexPolyhedron::Face& plane = owner.faces[face];
  const Vec3 normal_other = other_from_owner.rotation * plane.normal;
  const Vec3& deepest = other.vertices[other.SupportVertex(-normal_other)];
  // Plane in the other's frame: n'.x = d + n'.t.
  return normal_other.dot(deepest) - plane.offset - normal_other.dot(other_from_owner.translation);
}

// Face queries first: if a face separates, the costlier edge query is
// skipped. The best feature is face A, then face B, then the edges, each
// only when strictly better, so ties resolve the same way every time.
SatResult RunSat(const PairInA& frame, double early_out) {
  SatResult result;
  result.face_a = QueryFacesOfA(frame, early_out);
  result.separation = result.face_a.separation;
  result.witness = {SeparatingWitness::Type::kFaceA, result.face_a.face, -1};
  result.normal_world = frame.world_from_a.rotation * (-frame.a->faces[result.face_a.face].normal);
  if (result.separation > early_out) return result;
  result.face_b = QueryFacesOfB(frame, early_out);
  if (result.face_b.separation > result.separation) {
    result.separation = result.face_b.separation;
    result.witness = {SeparatingWitness::Type::kFaceB, -1, result.face_b.face};
    result.normal_world = frame.world_from_a.rotation * (*frame.b_normals)[result.face_b.face];
  }
  if (result.separation > early_out) return result;
  result.edges = QueryEdges(frame, early_out, result.separation);
  if (result.edges.separation > result.separation) {
    result.separation = result.edges.separation;
    result.witness = {SeparatingWitness::Type::kEdges, result.edges.edge_a, result.edges.edge_b};
    result.normal_world = result.edges.normal_world;
  }
  return result;
}

SatResult QueryPolyhedronSeparation(const ConvexPolyhedron& a, const Pose& world_from_a,
                                    const ConvexPolyhedron& b, const Pose& world_from_b) {
  assert(!a.faces.empty() && !b.faces.empty());
  const PolyhedronPair pair{&a, world_from_a, &b, world_from_b, 0.0};
  return RunSat(MakePairInA(pair), kInfinity);
}

}  // namespace rigid_body_sim::physics
