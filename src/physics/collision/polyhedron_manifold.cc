#include "physics/collision/polyhedron_manifold.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace rigid_body_sim::physics {
namespace {

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

FeatureId MakeFeatureId(const ClipVertex& vertex, const FaceContactInput& input,
                        int incident_face) {
  const auto u32 = [](int i) { return static_cast<std::uint32_t>(i); };
  const int reference_face = input.reference_face;
  switch (vertex.kind) {
    case ClipVertex::Kind::kIncidentVertex:
      return input.reference_is_a
                 ? FeatureId{FeatureType::kFaceVertex, u32(reference_face), u32(vertex.incident)}
                 : FeatureId{FeatureType::kVertexFace, u32(vertex.incident), u32(reference_face)};
    case ClipVertex::Kind::kEdgeCrossing:
      return input.reference_is_a
                 ? FeatureId{FeatureType::kEdgeEdge, u32(vertex.reference), u32(vertex.incident)}
                 : FeatureId{FeatureType::kEdgeEdge, u32(vertex.incident), u32(vertex.reference)};
    case ClipVertex::Kind::kReferenceVertex:
      return input.reference_is_a
                 ? FeatureId{FeatureType::kVertexFace, u32(vertex.reference), u32(incident_face)}
                 : FeatureId{FeatureType::kFaceVertex, u32(incident_face), u32(vertex.reference)};
  }
  return FeatureId{};
}

// The face of `incident` most anti-parallel to the reference normal, given
// in the incident shape's frame.
int IncidentFace(const ConvexPolyhedron& incident, const Vec3& normal_in_incident) {
  int incident_face = 0;
  double most_antiparallel = std::numeric_limits<double>::infinity();
  for (int f = 0; f < static_cast<int>(incident.faces.size()); ++f) {
    const double alignment = incident.faces[f].normal.dot(normal_in_incident);
    if (alignment < most_antiparallel) {
      most_antiparallel = alignment;
      incident_face = f;
    }
  }
  return incident_face;
}

// The incident face's polygon in world coordinates, each vertex labelled
// with the incident edge that leaves it.
void IncidentPolygon(const FaceContactInput& input, int incident_face,
                     std::vector<ClipVertex>* polygon) {
  const ConvexPolyhedron& incident = *input.incident;
  polygon->clear();
  const int first = incident.faces[incident_face].first_half_edge;
  int h = first;
  do {
    const int vertex = incident.half_edges[h].origin;
    polygon->push_back({input.world_from_incident * incident.vertices[vertex],
                        ClipVertex::Kind::kIncidentVertex, vertex, -1, h >> 1});
    h = incident.half_edges[h].next;
  } while (h != first);
}

// One side plane k of the reference face: the half-edge that runs along it
// and the next one, in world coordinates.
struct ReferenceSide {
  const ConvexPolyhedron* reference = nullptr;
  int index = 0;  // k, counting from the face's first half-edge
  int half_edge = -1;
  int next_half_edge = -1;
  Vec3 start;   // m, world
  Vec3 normal;  // m_k = (v_k+1 - v_k) x n, outward, not unit
};

// The crossing of the polygon side from p to q (labelled p.out_label) with
// side plane k: an incident edge gives an edge/edge point; a piece of an
// earlier side plane j gives the reference vertex where sides j and k meet.
ClipVertex Crossing(const ReferenceSide& side, const ClipVertex& p, const ClipVertex& q, double dp,
                    double dq, int out_label) {
  ClipVertex x;
  x.position = p.position + (q.position - p.position) * (dp / (dp - dq));
  x.out_label = out_label;
  if (p.out_label >= 0) {
    x.kind = ClipVertex::Kind::kEdgeCrossing;
    x.incident = p.out_label;
    x.reference = side.half_edge >> 1;
  } else {
    x.kind = ClipVertex::Kind::kReferenceVertex;
    // Sides are numbered in order, so side k-1 ends where side k starts;
    // crossings with non-adjacent sides lie outside the face and are
    // removed by a later plane.
    const bool follows_previous = ~p.out_label == side.index - 1;
    x.reference =
        side.reference->half_edges[follows_previous ? side.half_edge : side.next_half_edge].origin;
  }
  return x;
}

// Sutherland-Hodgman against one side plane: keeps the part of `polygon`
// with m_k.(p - start) <= 0 in `clipped`.
void ClipBySide(const ReferenceSide& side, const std::vector<ClipVertex>& polygon,
                std::vector<ClipVertex>* clipped) {
  thread_local std::vector<double> side_distance;
  const int n = static_cast<int>(polygon.size());
  side_distance.resize(n);
  for (int i = 0; i < n; ++i) side_distance[i] = side.normal.dot(polygon[i].position - side.start);
  clipped->clear();
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const ClipVertex& p = polygon[i];
    const ClipVertex& q = polygon[j];
    const double dp = side_distance[i];
    const double dq = side_distance[j];
    if (dp <= 0.0) {
      clipped->push_back(p);
      if (dq > 0.0) {
        if (dp < 0.0) {
          clipped->push_back(Crossing(side, p, q, dp, dq, ~side.index));
        } else {
          clipped->back().out_label = ~side.index;
        }
      }
    } else if (dq < 0.0) {
      clipped->push_back(Crossing(side, p, q, dp, dq, p.out_label));
    }
  }
}

// Clips `polygon` by every side plane of the reference face in turn.
void ClipToReferenceFace(const FaceContactInput& input, const Vec3& normal,
                         std::vector<ClipVertex>* polygon) {
  thread_local std::vector<ClipVertex> clipped;
  const ConvexPolyhedron& reference = *input.reference;
  const int first_side = reference.faces[input.reference_face].first_half_edge;
  ReferenceSide side;
  side.reference = &reference;
  side.half_edge = first_side;
  do {
    side.next_half_edge = reference.half_edges[side.half_edge].next;
    side.start = input.world_from_reference *
                 reference.vertices[reference.half_edges[side.half_edge].origin];
    const Vec3 end = input.world_from_reference *
                     reference.vertices[reference.half_edges[side.next_half_edge].origin];
    side.normal = (end - side.start).cross(normal);
    ClipBySide(side, *polygon, &clipped);
    polygon->swap(clipped);
    side.half_edge = side.next_half_edge;
    ++side.index;
  } while (side.half_edge != first_side && !polygon->empty());
}

}  // namespace

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

// Face contact (Sutherland and Hodgman 1974 clipping): the incident face is
// the face of the other shape most anti-parallel to the reference normal n;
// its polygon is clipped by the side planes of the reference face (normal
// m_k = (v_k+1 - v_k) x n, outward since faces run counter-clockwise).
// Points with s = n.p - d < contact distance are kept, moved to the middle
// between the surfaces (p - n s / 2). Each point keeps the features that
// produced it, so its id is the same whenever the configuration is.
bool BuildFaceContact(const FaceContactInput& input, ContactManifold* manifold) {
  thread_local std::vector<ClipVertex> polygon;
  thread_local std::vector<ContactPoint> kept;
  const ConvexPolyhedron& incident = *input.incident;
  const ConvexPolyhedron::Face& reference_plane = input.reference->faces[input.reference_face];
  const Vec3 normal = input.world_from_reference.rotation * reference_plane.normal;
  const double offset = reference_plane.offset + normal.dot(input.world_from_reference.translation);
  const Vec3 normal_in_incident = input.world_from_incident.rotation.conjugate() * normal;
  const int incident_face = IncidentFace(incident, normal_in_incident);
  IncidentPolygon(input, incident_face, &polygon);
  ClipToReferenceFace(input, normal, &polygon);

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
  manifold->points[0].feature = {FeatureType::kEdgeEdge, static_cast<std::uint32_t>(edge_a),
                                 static_cast<std::uint32_t>(edge_b)};
  manifold->point_count = 1;
  return true;
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
