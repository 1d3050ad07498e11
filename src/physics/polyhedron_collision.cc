#include "physics/polyhedron_collision.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

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

// Feature selection for contacts prefers a face of A, then a face of B, then
// an edge pair, unless the next one separates more by this tolerance
// (kRelativeFeatureBias |best| + kAbsoluteFeatureBias): nearly equal axes
// otherwise flip from step to step and the manifold with them (Gregorius,
// GDC 2013). The cached feature of last step is preferred first.
constexpr double kRelativeFeatureBias = 0.05;
constexpr double kAbsoluteFeatureBias = 1e-5;  // m

// The pair in the frame of A: B's vertices and face normals are mapped into
// it once per call.
struct PairInA {
  const ConvexPolyhedron* a = nullptr;
  const ConvexPolyhedron* b = nullptr;
  Pose world_from_a;
  Pose a_from_b;
  Mat3 b_from_a_matrix;                     // rotation, for the per-face queries
  std::vector<Vec3>* b_vertices = nullptr;  // m, frame A
  std::vector<Vec3>* b_normals = nullptr;   // unit, frame A
};

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
  for (std::size_t i = 0; i < b_vertices.size(); ++i) {
    b_vertices[i] = Multiply(rotation, pair.b->vertices[i]) + frame.a_from_b.translation;
  }
  b_normals.resize(pair.b->faces.size());
  for (std::size_t i = 0; i < b_normals.size(); ++i) {
    b_normals[i] = Multiply(rotation, pair.b->faces[i].normal);
  }
  frame.b_vertices = &b_vertices;
  frame.b_normals = &b_normals;
  return frame;
}

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
bool IsMinkowskiFace(const Vec3& na, const Vec3& nb, const Vec3& bxa, const Vec3& nc,
                     const Vec3& nd, const Vec3& dxc) {
  // Most pairs fail the first test; the rest is computed only when needed.
  const double cba = -nc.dot(bxa);
  const double dba = -nd.dot(bxa);
  if (!(cba * dba < 0.0)) return false;
  const double adc = na.dot(dxc);
  const double bdc = nb.dot(dxc);
  return adc * bdc < 0.0 && cba * bdc > 0.0;
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

// Best edge pair over the Minkowski-face pairs. On such a pair the edges are
// the supports of A along the axis and of B against it, so the separation is
// axis.(p_b - p_a) with any points on the two edges.
EdgeQuery QueryEdges(const PairInA& frame, double early_out) {
  thread_local std::vector<EdgeInA> b_edges;
  thread_local std::vector<Vec3> b_arc_normals;
  const int b_edge_count = frame.b->EdgeCount();
  b_edges.resize(b_edge_count);
  b_arc_normals.resize(b_edge_count);
  for (int e = 0; e < b_edge_count; ++e) {
    b_edges[e] = EdgeOfB(frame, e);
    b_arc_normals[e] = b_edges[e].normal_right.cross(b_edges[e].normal_left);
  }
  EdgeQuery query;
  Vec3 best_axis = Vec3::UnitZ();
  for (int ea = 0; ea < frame.a->EdgeCount(); ++ea) {
    const EdgeInA edge_a = EdgeOfA(frame, ea);
    const Vec3 bxa = edge_a.normal_right.cross(edge_a.normal_left);
    for (int eb = 0; eb < b_edge_count; ++eb) {
      const EdgeInA& edge_b = b_edges[eb];
      if (!IsMinkowskiFace(edge_a.normal_left, edge_a.normal_right, bxa, edge_b.normal_left,
                           edge_b.normal_right, b_arc_normals[eb])) {
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
  result.edges = QueryEdges(frame, early_out);
  if (result.edges.separation > result.separation) {
    result.separation = result.edges.separation;
    result.witness = {SeparatingWitness::Type::kEdges, result.edges.edge_a, result.edges.edge_b};
    result.normal_world = result.edges.normal_world;
  }
  return result;
}

// A point of the clipped polygon and the features that made it.
struct ClipVertex {
  enum class Kind : std::uint8_t { kIncidentVertex, kEdgeCrossing, kReferenceVertex };
  Vec3 position;  // m, world
  Kind kind = Kind::kIncidentVertex;
  int incident = -1;   // incident vertex or incident edge
  int reference = -1;  // reference edge or reference vertex
  // The polygon side from this point to the next: an incident edge index
  // (>= 0) or ~k for a piece of reference side plane k.
  int out_label = 0;
};

struct FaceContactInput {
  const ConvexPolyhedron* reference = nullptr;
  Pose world_from_reference;
  int reference_face = -1;
  const ConvexPolyhedron* incident = nullptr;
  Pose world_from_incident;
  bool reference_is_a = true;
  double contact_distance = 0.0;  // m
};

FeatureId MakeFeatureId(const ClipVertex& vertex, const FaceContactInput& input,
                        int incident_face) {
  const auto u16 = [](int i) { return static_cast<std::uint16_t>(i); };
  const int reference_face = input.reference_face;
  switch (vertex.kind) {
    case ClipVertex::Kind::kIncidentVertex:
      return input.reference_is_a
                 ? FeatureId{FeatureType::kFaceVertex, u16(reference_face), u16(vertex.incident)}
                 : FeatureId{FeatureType::kVertexFace, u16(vertex.incident), u16(reference_face)};
    case ClipVertex::Kind::kEdgeCrossing:
      return input.reference_is_a
                 ? FeatureId{FeatureType::kEdgeEdge, u16(vertex.reference), u16(vertex.incident)}
                 : FeatureId{FeatureType::kEdgeEdge, u16(vertex.incident), u16(vertex.reference)};
    case ClipVertex::Kind::kReferenceVertex:
      return input.reference_is_a
                 ? FeatureId{FeatureType::kVertexFace, u16(vertex.reference), u16(incident_face)}
                 : FeatureId{FeatureType::kFaceVertex, u16(incident_face), u16(vertex.reference)};
  }
  return FeatureId{};
}

// Face contact (Sutherland and Hodgman 1974 clipping): the incident face is
// the face of the other shape most anti-parallel to the reference normal n;
// its polygon is clipped by the side planes of the reference face (normal
// m_k = (v_k+1 - v_k) x n, outward since faces run counter-clockwise).
// Points with s = n.p - d < contact distance are kept, moved to the middle
// between the surfaces (p - n s / 2). Each point keeps the features that
// produced it, so its id is the same whenever the configuration is.
bool BuildFaceContact(const FaceContactInput& input, ContactManifold* manifold) {
  thread_local std::vector<ClipVertex> polygon;
  thread_local std::vector<ClipVertex> clipped;
  thread_local std::vector<double> side_distance;
  thread_local std::vector<ContactPoint> kept;
  const ConvexPolyhedron& reference = *input.reference;
  const ConvexPolyhedron& incident = *input.incident;
  const ConvexPolyhedron::Face& reference_plane = reference.faces[input.reference_face];
  const Vec3 normal = input.world_from_reference.rotation * reference_plane.normal;
  const double offset = reference_plane.offset + normal.dot(input.world_from_reference.translation);

  const Vec3 normal_in_incident = input.world_from_incident.rotation.conjugate() * normal;
  int incident_face = 0;
  double most_antiparallel = kInfinity;
  for (int f = 0; f < static_cast<int>(incident.faces.size()); ++f) {
    const double alignment = incident.faces[f].normal.dot(normal_in_incident);
    if (alignment < most_antiparallel) {
      most_antiparallel = alignment;
      incident_face = f;
    }
  }

  polygon.clear();
  {
    const int first = incident.faces[incident_face].first_half_edge;
    int h = first;
    do {
      const int vertex = incident.half_edges[h].origin;
      polygon.push_back({input.world_from_incident * incident.vertices[vertex],
                         ClipVertex::Kind::kIncidentVertex, vertex, -1, h >> 1});
      h = incident.half_edges[h].next;
    } while (h != first);
  }

  const int first_side = reference_plane.first_half_edge;
  int side_half_edge = first_side;
  int side = 0;
  do {
    const int next_half_edge = reference.half_edges[side_half_edge].next;
    const Vec3 start = input.world_from_reference *
                       reference.vertices[reference.half_edges[side_half_edge].origin];
    const Vec3 end = input.world_from_reference *
                     reference.vertices[reference.half_edges[next_half_edge].origin];
    const Vec3 side_normal = (end - start).cross(normal);
    const int n = static_cast<int>(polygon.size());
    side_distance.resize(n);
    for (int i = 0; i < n; ++i) side_distance[i] = side_normal.dot(polygon[i].position - start);
    clipped.clear();
    // The crossing of the polygon side labelled `label` with side plane k:
    // an incident edge gives an edge/edge point; a piece of an earlier side
    // plane j gives the reference vertex where sides j and k meet.
    const auto crossing = [&](const ClipVertex& p, const ClipVertex& q, double dp, double dq,
                              int out_label) {
      ClipVertex x;
      x.position = p.position + (q.position - p.position) * (dp / (dp - dq));
      x.out_label = out_label;
      if (p.out_label >= 0) {
        x.kind = ClipVertex::Kind::kEdgeCrossing;
        x.incident = p.out_label;
        x.reference = side_half_edge >> 1;
      } else {
        x.kind = ClipVertex::Kind::kReferenceVertex;
        // Sides are numbered in order, so side k-1 ends where side k starts;
        // crossings with non-adjacent sides lie outside the face and are
        // removed by a later plane.
        const bool follows_previous = ~p.out_label == side - 1;
        x.reference =
            reference.half_edges[follows_previous ? side_half_edge : next_half_edge].origin;
      }
      return x;
    };
    for (int i = 0; i < n; ++i) {
      const int j = (i + 1) % n;
      const ClipVertex& p = polygon[i];
      const ClipVertex& q = polygon[j];
      const double dp = side_distance[i];
      const double dq = side_distance[j];
      if (dp <= 0.0) {
        clipped.push_back(p);
        if (dq > 0.0) {
          if (dp < 0.0) {
            clipped.push_back(crossing(p, q, dp, dq, ~side));
          } else {
            clipped.back().out_label = ~side;
          }
        }
      } else if (dq < 0.0) {
        clipped.push_back(crossing(p, q, dp, dq, p.out_label));
      }
    }
    polygon.swap(clipped);
    side_half_edge = next_half_edge;
    ++side;
  } while (side_half_edge != first_side && !polygon.empty());

  kept.clear();
  for (const ClipVertex& vertex : polygon) {
    const double separation = normal.dot(vertex.position) - offset;
    if (separation < input.contact_distance) {
      kept.push_back({vertex.position - 0.5 * separation * normal, separation,
                      MakeFeatureId(vertex, input, incident_face)});
    }
  }
  if (kept.empty()) {
    // The clip lost the deepest point (it can lie outside the reference
    // face's prism, e.g. a vertex just past a face edge); the incident
    // support vertex along -n is then the single contact.
    const int vertex = incident.SupportVertex(-normal_in_incident);
    const Vec3 position = input.world_from_incident * incident.vertices[vertex];
    const double separation = normal.dot(position) - offset;
    if (!(separation < input.contact_distance)) {
      manifold->point_count = 0;
      return false;
    }
    ClipVertex support;
    support.kind = ClipVertex::Kind::kIncidentVertex;
    support.incident = vertex;
    kept.push_back({position - 0.5 * separation * normal, separation,
                    MakeFeatureId(support, input, incident_face)});
  }
  const Vec3 normal_b_to_a = input.reference_is_a ? Vec3(-normal) : normal;
  ReduceContactPoints(kept.data(), static_cast<int>(kept.size()), normal_b_to_a, manifold);
  return true;
}

// Closest points of segments p0 + s d1 and q0 + t d2, s, t in [0, 1]:
// minimise |p0 + s d1 - q0 - t d2|^2; the unconstrained s is clamped, t
// follows from s and is clamped, and s is recomputed from the clamped t.
void ClosestPointsOfSegments(const Vec3& p0, const Vec3& d1, const Vec3& q0, const Vec3& d2,
                             Vec3* on_p, Vec3* on_q) {
  const Vec3 r = p0 - q0;
  const double a = d1.squaredNorm();
  const double e = d2.squaredNorm();
  const double b = d1.dot(d2);
  const double c = d1.dot(r);
  const double f = d2.dot(r);
  const double denominator = a * e - b * b;
  double s = denominator > 0.0 ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  *on_p = p0 + s * d1;
  *on_q = q0 + t * d2;
}

// Baraff's edge/edge contact: one point midway between the closest points
// of the two edges.
bool BuildEdgeContact(const PolyhedronPair& pair, int edge_a, int edge_b, double separation,
                      const Vec3& normal_world, ContactManifold* manifold) {
  const ConvexPolyhedron& a = *pair.a;
  const ConvexPolyhedron& b = *pair.b;
  const Vec3 a0 = pair.world_from_a * a.vertices[a.half_edges[2 * edge_a].origin];
  const Vec3 a1 = pair.world_from_a * a.vertices[a.half_edges[2 * edge_a + 1].origin];
  const Vec3 b0 = pair.world_from_b * b.vertices[b.half_edges[2 * edge_b].origin];
  const Vec3 b1 = pair.world_from_b * b.vertices[b.half_edges[2 * edge_b + 1].origin];
  Vec3 on_a;
  Vec3 on_b;
  ClosestPointsOfSegments(a0, a1 - a0, b0, b1 - b0, &on_a, &on_b);
  manifold->normal_world = normal_world;
  manifold->points[0].position_world = 0.5 * (on_a + on_b);
  manifold->points[0].separation = separation;
  manifold->points[0].feature = {FeatureType::kEdgeEdge, static_cast<std::uint16_t>(edge_a),
                                 static_cast<std::uint16_t>(edge_b)};
  manifold->point_count = 1;
  return true;
}

}  // namespace

SatResult QueryPolyhedronSeparation(const ConvexPolyhedron& a, const Pose& world_from_a,
                                    const ConvexPolyhedron& b, const Pose& world_from_b) {
  assert(!a.faces.empty() && !b.faces.empty());
  const PolyhedronPair pair{&a, world_from_a, &b, world_from_b, 0.0};
  return RunSat(MakePairInA(pair), kInfinity);
}

bool CollidePolyhedra(const PolyhedronPair& pair, SeparatingWitness* witness,
                      ContactManifold* manifold, CollideStats* stats) {
  assert(pair.a != nullptr && pair.b != nullptr && manifold != nullptr);
  assert(!pair.a->faces.empty() && !pair.b->faces.empty());
  CollideStats local_stats;
  if (stats == nullptr) stats = &local_stats;
  *stats = CollideStats{};
  manifold->point_count = 0;
  SeparatingWitness cached;
  if (witness != nullptr) cached = *witness;
  const double face_separation = FaceWitnessSeparation(pair, cached);
  if (face_separation > pair.contact_distance) {
    stats->witness_early_out = true;
    stats->gap = face_separation;
    return false;
  }
  const PairInA frame = MakePairInA(pair);

  // A face witness was measured above; an edge witness needs B in A's frame.
  Vec3 cached_edge_normal = Vec3::UnitZ();
  bool cached_edges_still_face = false;
  const double cached_separation =
      cached.type == SeparatingWitness::Type::kEdges
          ? EdgeWitnessSeparation(frame, cached, &cached_edge_normal, &cached_edges_still_face)
          : face_separation;
  if (cached_separation > pair.contact_distance) {
    stats->witness_early_out = true;
    stats->gap = cached_separation;
    return false;
  }

  const SatResult sat = RunSat(frame, pair.contact_distance);
  if (sat.separation > pair.contact_distance) {
    if (witness != nullptr) *witness = sat.witness;
    stats->gap = sat.separation;
    return false;
  }

  const double tolerance = kRelativeFeatureBias * std::abs(sat.separation) + kAbsoluteFeatureBias;
  const double acceptable = sat.separation - tolerance;
  SeparatingWitness chosen;
  double chosen_separation = 0.0;
  Vec3 chosen_edge_normal = sat.edges.normal_world;
  const bool cached_usable =
      cached.type != SeparatingWitness::Type::kEdges || cached_edges_still_face;
  if (cached.type != SeparatingWitness::Type::kNone && cached_usable &&
      cached_separation >= acceptable) {
    chosen = cached;
    chosen_separation = cached_separation;
    chosen_edge_normal = cached_edge_normal;
    stats->witness_kept = true;
  } else if (sat.face_a.separation >= acceptable) {
    chosen = {SeparatingWitness::Type::kFaceA, sat.face_a.face, -1};
  } else if (sat.face_b.separation >= acceptable) {
    chosen = {SeparatingWitness::Type::kFaceB, -1, sat.face_b.face};
  } else {
    chosen = {SeparatingWitness::Type::kEdges, sat.edges.edge_a, sat.edges.edge_b};
    chosen_separation = sat.edges.separation;
  }
  if (witness != nullptr) *witness = chosen;

  switch (chosen.type) {
    case SeparatingWitness::Type::kFaceA:
      return BuildFaceContact({pair.a, pair.world_from_a, chosen.index_a, pair.b, pair.world_from_b,
                               true, pair.contact_distance},
                              manifold);
    case SeparatingWitness::Type::kFaceB:
      return BuildFaceContact({pair.b, pair.world_from_b, chosen.index_b, pair.a, pair.world_from_a,
                               false, pair.contact_distance},
                              manifold);
    case SeparatingWitness::Type::kEdges:
      if (!(chosen_separation < pair.contact_distance)) return false;
      return BuildEdgeContact(pair, chosen.index_a, chosen.index_b, chosen_separation,
                              chosen_edge_normal, manifold);
    case SeparatingWitness::Type::kNone:
      break;
  }
  return false;
}

// Keeps the deepest point (it carries the largest correction), then the
// point furthest from it, then the point maximising |triangle area| and
// finally the point adding the most area outside the triangle: a large
// support polygon with few points keeps resting stacks stable.
void ReduceContactPoints(const ContactPoint* points, int count, const Vec3& normal_world,
                         ContactManifold* manifold) {
  assert(count >= 0);
  manifold->normal_world = normal_world;
  if (count <= ContactManifold::kMaxPoints) {
    for (int i = 0; i < count; ++i) manifold->points[i] = points[i];
    manifold->point_count = count;
    return;
  }
  int first = 0;
  for (int i = 1; i < count; ++i) {
    if (points[i].separation < points[first].separation) first = i;
  }
  const Vec3& p0 = points[first].position_world;
  int second = first;
  double furthest = -1.0;
  for (int i = 0; i < count; ++i) {
    const double distance_squared = (points[i].position_world - p0).squaredNorm();
    if (distance_squared > furthest) {
      furthest = distance_squared;
      second = i;
    }
  }
  const Vec3& p1 = points[second].position_world;
  const auto signed_area = [&](const Vec3& x, const Vec3& y, const Vec3& z) {
    return (y - x).cross(z - x).dot(normal_world);
  };
  int third = first;
  double largest = -1.0;
  for (int i = 0; i < count; ++i) {
    const double area = std::abs(signed_area(p0, p1, points[i].position_world));
    if (area > largest) {
      largest = area;
      third = i;
    }
  }
  // Orient the triangle counter-clockwise about the normal, so a point is
  // outside edge (x, y) when the signed area of (x, y, point) is negative.
  int triangle[3] = {first, second, third};
  if (signed_area(p0, p1, points[third].position_world) < 0.0) std::swap(triangle[0], triangle[1]);
  int fourth = -1;
  double largest_added = 0.0;
  for (int i = 0; i < count; ++i) {
    if (i == first || i == second || i == third) continue;
    double added = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double area =
          -signed_area(points[triangle[k]].position_world,
                       points[triangle[(k + 1) % 3]].position_world, points[i].position_world);
      added = std::max(added, area);
    }
    if (added > largest_added) {
      largest_added = added;
      fourth = i;
    }
  }
  int n = 0;
  manifold->points[n++] = points[first];
  if (second != first) manifold->points[n++] = points[second];
  if (third != first && third != second) manifold->points[n++] = points[third];
  if (fourth >= 0) manifold->points[n++] = points[fourth];
  manifold->point_count = n;
}

}  // namespace rigid_body_sim::physics
