#include "physics/collision/cylinder_collision.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "physics/collision/polyhedron_collision.h"
#include "physics/collision/polyhedron_manifold.h"

namespace rigid_body_sim::physics {
namespace {

// Rim points of the cap that faces the other shape. Eight points at 45
// degrees, the first at the rim's deepest point, so a cylinder standing on
// its cap is supported by an octagon whose corner lies where it would tip.
constexpr int kCapPoints = 8;
// Axes whose separations differ by less than this are equally good; the
// earlier kind (a face of the other shape, then the cap) is kept, because
// its manifold has the most points.
constexpr double kTieTolerance = 1e-9;  // m

// The cylinder in the world frame.
struct WorldCylinder {
  Vec3 centre;
  Vec3 axis;  // unit, the shape's z axis
  double radius;
  double half_length;

  // min over the cylinder of L.x for a unit L: the support in -L,
  // L.c - h |L.a| - r sqrt(1 - (L.a)^2).
  double MinAlong(const Vec3& direction) const {
    const double along_axis = direction.dot(axis);
    return direction.dot(centre) - half_length * std::abs(along_axis) -
           radius * std::sqrt(std::max(0.0, 1.0 - along_axis * along_axis));
  }
};

WorldCylinder ToWorld(const Cylinder& cylinder, const Pose& world_from_cylinder) {
  return WorldCylinder{world_from_cylinder.translation,
                       world_from_cylinder.rotation * Vec3::UnitZ(), cylinder.radius,
                       cylinder.half_length};
}

// The cylinder's candidate contact points towards `toward_other` (world,
// unit). With m the direction in the shape frame and u the unit radial part
// of m (any radial unit when m is along the axis): the far cap's rim point
// r u, and the facing cap's rim at r (cos(k pi/4) u + sin(k pi/4) v). The
// side line from the far point to the facing cap's first point is where a
// cylinder lying on its side touches.
struct IncidentPoints {
  Vec3 far_side;                         // world
  std::array<Vec3, kCapPoints> cap_rim;  // world, counter-clockwise seen from outside or not
};

IncidentPoints CylinderIncident(const Cylinder& cylinder, const Pose& world_from_cylinder,
                                const Vec3& toward_other) {
  const Vec3 m = world_from_cylinder.rotation.conjugate() * toward_other;
  const Vec3 radial(m.x(), m.y(), 0.0);
  const double radial_norm = radial.norm();
  const Vec3 u = radial_norm > 1e-12 ? Vec3(radial / radial_norm) : Vec3::UnitX();
  const Vec3 v = Vec3::UnitZ().cross(u);
  const double facing_z = m.z() >= 0.0 ? cylinder.half_length : -cylinder.half_length;
  IncidentPoints points;
  points.far_side = world_from_cylinder * Vec3(cylinder.radius * u + Vec3(0, 0, -facing_z));
  for (int k = 0; k < kCapPoints; ++k) {
    const double angle = 2.0 * kPi * k / kCapPoints;
    const Vec3 rim = cylinder.radius * (std::cos(angle) * u + std::sin(angle) * v);
    points.cap_rim[k] = world_from_cylinder * Vec3(rim + Vec3(0, 0, facing_z));
  }
  return points;
}

// Sutherland and Hodgman (1974): the part of a convex polygon (or segment)
// on the inner side of the plane m.x <= offset.
void ClipByPlane(const Vec3& normal, double offset, std::vector<Vec3>* polygon) {
  std::vector<Vec3> clipped;
  const int count = static_cast<int>(polygon->size());
  for (int i = 0; i < count; ++i) {
    const Vec3& from = (*polygon)[i];
    const Vec3& to = (*polygon)[(i + 1) % count];
    const double from_distance = normal.dot(from) - offset;
    const double to_distance = normal.dot(to) - offset;
    if (from_distance <= 0.0) clipped.push_back(from);
    if ((from_distance <= 0.0) != (to_distance <= 0.0)) {
      const double t = from_distance / (from_distance - to_distance);
      clipped.push_back(from + t * (to - from));
    }
  }
  // A segment is walked there and back, so it meets a plane twice.
  if (count == 2 && clipped.size() > 2) clipped.resize(2);
  *polygon = std::move(clipped);
}

}  // namespace

Vec3 CylinderSupport(const Cylinder& cylinder, const Vec3& direction) {
  const Vec3 radial(direction.x(), direction.y(), 0.0);
  const double radial_norm = radial.norm();
  const Vec3 rim = radial_norm > 0.0 ? Vec3(cylinder.radius * radial / radial_norm) : Vec3::Zero();
  return rim + Vec3(0, 0, direction.z() >= 0.0 ? cylinder.half_length : -cylinder.half_length);
}

Vec3 ClosestPointOnCylinder(const Cylinder& cylinder, const Vec3& point) {
  const Vec3 radial(point.x(), point.y(), 0.0);
  const double radial_norm = radial.norm();
  const Vec3 clamped_radial =
      radial_norm > cylinder.radius ? Vec3(radial * (cylinder.radius / radial_norm)) : radial;
  return clamped_radial +
         Vec3(0, 0, std::clamp(point.z(), -cylinder.half_length, cylinder.half_length));
}

// Cylinder against the plane n.x = n.t_b: its deepest point is at
// n.c - h |n.a| - r sqrt(1 - (n.a)^2) (its support in -n). The candidates are
// the far cap's deepest rim point and the facing cap's rim octagon; each with
// s = n.(p - t_b) below the contact distance is a point, moved halfway to the
// plane.
bool CollideCylinderHalfSpace(const CylinderPair& pair, ContactManifold* manifold) {
  const Vec3 normal = pair.world_from_other.rotation * Vec3::UnitZ();
  const WorldCylinder cylinder = ToWorld(*pair.cylinder, pair.world_from_cylinder);
  const double plane = normal.dot(pair.world_from_other.translation);
  if (!(cylinder.MinAlong(normal) - plane < pair.contact_distance)) return false;
  const IncidentPoints incident =
      CylinderIncident(*pair.cylinder, pair.world_from_cylinder, -normal);
  std::array<ContactPoint, kCapPoints + 1> kept;
  int count = 0;
  auto keep = [&](const Vec3& point, int index) {
    const double separation = normal.dot(point) - plane;
    if (!(separation < pair.contact_distance)) return;
    kept[count++] = {point - 0.5 * separation * normal, separation,
                     FeatureId{FeatureType::kVertexFace, static_cast<std::uint32_t>(index), 0}};
  };
  keep(incident.far_side, kCapPoints);
  for (int k = 0; k < kCapPoints; ++k) keep(incident.cap_rim[k], k);
  ReduceContactPoints(kept.data(), count, normal, manifold);
  return manifold->point_count > 0;
}

// Closest point q of the solid cylinder to the sphere's centre p (cylinder
// frame). Outside: n = (p - q) / |p - q|, distance |p - q|. Inside: the
// nearer of the side (distance r - rho, radial normal) and the cap
// (h - |z|, axial normal), as a negative distance. s = distance - R.
bool CollideCylinderSphere(const CylinderPair& pair, const Sphere& sphere,
                           ContactManifold* manifold) {
  const Cylinder& cylinder = *pair.cylinder;
  const Vec3 centre = pair.world_from_cylinder.Inverse() * pair.world_from_other.translation;
  const Vec3 radial(centre.x(), centre.y(), 0.0);
  const double rho = radial.norm();
  const double side_depth = cylinder.radius - rho;
  const double cap_depth = cylinder.half_length - std::abs(centre.z());
  Vec3 surface = ClosestPointOnCylinder(cylinder, centre);
  Vec3 outward = Vec3::UnitZ();
  double distance = 0.0;
  if (side_depth >= 0.0 && cap_depth >= 0.0) {
    if (cap_depth <= side_depth) {
      outward = Vec3(0, 0, centre.z() >= 0.0 ? 1.0 : -1.0);
      surface = Vec3(centre.x(), centre.y(), outward.z() * cylinder.half_length);
      distance = -cap_depth;
    } else {
      outward = rho > 0.0 ? Vec3(radial / rho) : Vec3::UnitX();
      surface = cylinder.radius * outward + Vec3(0, 0, centre.z());
      distance = -side_depth;
    }
  } else {
    distance = (centre - surface).norm();
    outward = (centre - surface) / distance;
  }
  const double separation = distance - sphere.radius;
  if (!(separation < pair.contact_distance)) return false;
  const Vec3 outward_world = pair.world_from_cylinder.rotation * outward;
  const Vec3 surface_world = pair.world_from_cylinder * surface;
  const Vec3 sphere_point = pair.world_from_other.translation - sphere.radius * outward_world;
  manifold->normal_world = -outward_world;
  manifold->points[0] = {0.5 * (surface_world + sphere_point), separation, FeatureId{}};
  manifold->point_count = 1;
  return true;
}

namespace {

// A candidate separating axis L (unit, from the polyhedron B to the
// cylinder A) with s(L) = min_A L.x - max_B L.y and the pair of points that
// proposed it.
struct CylinderAxis {
  enum class Kind : std::uint8_t { kFaceB, kCap, kPoints };
  Kind kind = Kind::kPoints;
  Vec3 normal = Vec3::UnitZ();
  double separation = -std::numeric_limits<double>::infinity();
  int face = -1;                // kFaceB
  Vec3 point_a = Vec3::Zero();  // kPoints: on the cylinder
  Vec3 point_b = Vec3::Zero();  // kPoints: on the polyhedron
};

struct PolyhedronInWorld {
  const ConvexPolyhedron* shape;
  const Pose* world_from_shape;
  std::vector<Vec3> vertices;  // world

  double MaxAlong(const Vec3& direction) const {
    const int v = shape->SupportVertex(world_from_shape->rotation.conjugate() * direction);
    return direction.dot(vertices[v]);
  }
};

// The point of segment start-end closest to the cylinder, and its closest
// point on the cylinder. The distance to a convex set is convex along a
// line, so a golden-section search (Kiefer, "Sequential minimax search for
// a maximum", 1953) over the segment's parameter finds its minimum; 60
// rounds shrink the bracket by 0.618^60 = 3e-13.
template <typename ClosestOnCylinder>
std::pair<Vec3, Vec3> EdgeClosestToCylinder(const Vec3& start, const Vec3& end,
                                            const ClosestOnCylinder& closest_on_cylinder) {
  constexpr double kInverseGolden = 0.6180339887498949;
  auto distance = [&](double t) {
    const Vec3 point = start + t * (end - start);
    return (closest_on_cylinder(point) - point).squaredNorm();
  };
  double low = 0.0;
  double high = 1.0;
  double left = high - kInverseGolden * (high - low);
  double right = low + kInverseGolden * (high - low);
  double left_distance = distance(left);
  double right_distance = distance(right);
  for (int round = 0; round < 60; ++round) {
    if (left_distance <= right_distance) {
      high = right;
      right = left;
      right_distance = left_distance;
      left = high - kInverseGolden * (high - low);
      left_distance = distance(left);
    } else {
      low = left;
      left = right;
      left_distance = right_distance;
      right = low + kInverseGolden * (high - low);
      right_distance = distance(right);
    }
  }
  double t = 0.5 * (low + high);
  if (distance(0.0) <= distance(t)) t = 0.0;
  if (distance(1.0) < distance(t)) t = 1.0;
  const Vec3 point = start + t * (end - start);
  return {point, closest_on_cylinder(point)};
}

// The separating-axis test over the axes that can define a cylinder's
// contact with a polyhedron: B's face normals, the cylinder's axis (its
// caps), a x e for every edge e of B (an edge against the side), and the
// direction from each vertex of B to its closest point on the cylinder or,
// for a vertex inside, the side normal there; and for each edge, the
// direction between its closest point to the cylinder and that point's
// closest point on the cylinder (an edge against a rim). When the shapes are
// apart, their closest features are a face of B, or an edge or vertex of B,
// against some point of the cylinder, so the test is exact; when they
// overlap, it is exact for the face, cap, side/edge and vertex cases.
CylinderAxis BestAxis(const CylinderPair& pair, const WorldCylinder& cylinder,
                      const PolyhedronInWorld& polyhedron) {
  CylinderAxis best;
  auto consider = [&](CylinderAxis axis) {
    axis.separation = cylinder.MinAlong(axis.normal) - polyhedron.MaxAlong(axis.normal);
    if (axis.separation > best.separation + kTieTolerance) best = axis;
  };
  const ConvexPolyhedron& shape = *polyhedron.shape;
  for (int f = 0; f < static_cast<int>(shape.faces.size()); ++f) {
    consider({CylinderAxis::Kind::kFaceB, pair.world_from_other.rotation * shape.faces[f].normal,
              0.0, f, Vec3::Zero(), Vec3::Zero()});
  }
  consider({CylinderAxis::Kind::kCap, cylinder.axis, 0.0, -1, Vec3::Zero(), Vec3::Zero()});
  consider({CylinderAxis::Kind::kCap, -cylinder.axis, 0.0, -1, Vec3::Zero(), Vec3::Zero()});
  const Cylinder local{cylinder.radius, cylinder.half_length};
  const Pose& world_from_cylinder = pair.world_from_cylinder;
  const Pose cylinder_from_world = world_from_cylinder.Inverse();
  auto closest_on_cylinder = [&](const Vec3& point) {
    return Vec3(world_from_cylinder * ClosestPointOnCylinder(local, cylinder_from_world * point));
  };
  const Vec3 axis_start = cylinder.centre - cylinder.half_length * cylinder.axis;
  const Vec3 axis_end = cylinder.centre + cylinder.half_length * cylinder.axis;
  for (const Vec3& vertex : polyhedron.vertices) {
    const Vec3 closest = closest_on_cylinder(vertex);
    const Vec3 gap = closest - vertex;
    if (gap.norm() > 1e-12) {
      consider({CylinderAxis::Kind::kPoints, gap.normalized(), 0.0, -1, closest, vertex});
      continue;
    }
    const Vec3 offset = vertex - cylinder.centre;
    const Vec3 radial = offset - offset.dot(cylinder.axis) * cylinder.axis;
    if (radial.norm() < 1e-12) continue;
    const Vec3 outward = radial.normalized();
    consider({CylinderAxis::Kind::kPoints, -outward, 0.0, -1,
              vertex - radial + cylinder.radius * outward, vertex});
  }
  for (int e = 0; e < shape.EdgeCount(); ++e) {
    const Vec3& start = polyhedron.vertices[shape.half_edges[2 * e].origin];
    const Vec3& end = polyhedron.vertices[shape.half_edges[2 * e + 1].origin];
    Vec3 on_axis;
    Vec3 on_edge;
    ClosestPointsOfSegments(axis_start, axis_end - axis_start, start, end - start, &on_axis,
                            &on_edge);
    Vec3 across = cylinder.axis.cross(end - start);
    if (across.norm() > 1e-9 * (end - start).norm()) {
      across.normalize();
      if (across.dot(on_axis - on_edge) < 0.0) across = -across;
      consider({CylinderAxis::Kind::kPoints, across, 0.0, -1,
                Vec3(on_axis - cylinder.radius * across), on_edge});
    }
    const auto [point, closest] = EdgeClosestToCylinder(start, end, closest_on_cylinder);
    const Vec3 gap = closest - point;
    if (gap.norm() > 1e-12) {
      consider({CylinderAxis::Kind::kPoints, gap.normalized(), 0.0, -1, closest, point});
    }
  }
  return best;
}

// Face f of B is the reference: the cylinder's side line and facing rim
// octagon are clipped by the face's side planes (m_k = edge_k x n) and kept
// where s = n.p - d_f is below the contact distance.
void FaceManifold(const CylinderPair& pair, const PolyhedronInWorld& polyhedron,
                  const CylinderAxis& axis, std::vector<ContactPoint>* points) {
  const Vec3& normal = axis.normal;
  const ConvexPolyhedron& shape = *polyhedron.shape;
  const std::vector<int> face_vertices = shape.FaceVertices(axis.face);
  const double plane = normal.dot(polyhedron.vertices[face_vertices[0]]);
  const IncidentPoints incident =
      CylinderIncident(*pair.cylinder, pair.world_from_cylinder, -normal);
  std::vector<Vec3> side = {incident.far_side, incident.cap_rim[0]};
  std::vector<Vec3> cap(incident.cap_rim.begin(), incident.cap_rim.end());
  const int count = static_cast<int>(face_vertices.size());
  for (int k = 0; k < count; ++k) {
    const Vec3& from = polyhedron.vertices[face_vertices[k]];
    const Vec3& to = polyhedron.vertices[face_vertices[(k + 1) % count]];
    const Vec3 side_normal = (to - from).cross(normal);
    ClipByPlane(side_normal, side_normal.dot(from), &side);
    ClipByPlane(side_normal, side_normal.dot(from), &cap);
  }
  int index = 0;
  for (const std::vector<Vec3>* polygon : {&side, &cap}) {
    for (const Vec3& point : *polygon) {
      // The side line ends at the cap's first rim point, which the cap
      // polygon holds already.
      if (polygon == &side && point == incident.cap_rim[0]) continue;
      const double separation = normal.dot(point) - plane;
      if (separation < pair.contact_distance) {
        const FeatureId feature{FeatureType::kVertexFace, static_cast<std::uint32_t>(index),
                                static_cast<std::uint32_t>(axis.face)};
        points->push_back({point - 0.5 * separation * normal, separation, feature});
      }
      ++index;
    }
  }
}

// A cap is the reference: the vertices of B within the cap's disc, with
// s = (L.c - h) - L.v below the contact distance.
void CapManifold(const CylinderPair& pair, const WorldCylinder& cylinder,
                 const PolyhedronInWorld& polyhedron, const CylinderAxis& axis,
                 std::vector<ContactPoint>* points) {
  const Vec3& normal = axis.normal;
  const double cap_plane = normal.dot(cylinder.centre) - cylinder.half_length;
  for (int v = 0; v < static_cast<int>(polyhedron.vertices.size()); ++v) {
    const Vec3& vertex = polyhedron.vertices[v];
    const Vec3 offset = vertex - cylinder.centre;
    const Vec3 radial = offset - offset.dot(cylinder.axis) * cylinder.axis;
    const double separation = cap_plane - normal.dot(vertex);
    if (radial.norm() <= cylinder.radius && separation < pair.contact_distance) {
      const FeatureId feature{FeatureType::kFaceVertex, 0, static_cast<std::uint32_t>(v)};
      points->push_back({vertex + 0.5 * separation * normal, separation, feature});
    }
  }
}

}  // namespace

bool CollideCylinderPolyhedron(const CylinderPair& pair, const ConvexPolyhedron& polyhedron,
                               ContactManifold* manifold) {
  const WorldCylinder cylinder = ToWorld(*pair.cylinder, pair.world_from_cylinder);
  thread_local PolyhedronInWorld world_polyhedron{nullptr, nullptr, {}};
  world_polyhedron.shape = &polyhedron;
  world_polyhedron.world_from_shape = &pair.world_from_other;
  world_polyhedron.vertices.resize(polyhedron.vertices.size());
  for (std::size_t v = 0; v < polyhedron.vertices.size(); ++v) {
    world_polyhedron.vertices[v] = pair.world_from_other * polyhedron.vertices[v];
  }
  const CylinderAxis axis = BestAxis(pair, cylinder, world_polyhedron);
  if (!(axis.separation < pair.contact_distance)) return false;
  thread_local std::vector<ContactPoint> points;
  points.clear();
  if (axis.kind == CylinderAxis::Kind::kFaceB) {
    FaceManifold(pair, world_polyhedron, axis, &points);
  } else if (axis.kind == CylinderAxis::Kind::kCap) {
    CapManifold(pair, cylinder, world_polyhedron, axis, &points);
  }
  if (points.empty()) {
    // One point for the defining feature, midway between the cylinder's
    // deepest point along -L and the polyhedron's along L.
    Vec3 point_a = axis.point_a;
    Vec3 point_b = axis.point_b;
    if (axis.kind != CylinderAxis::Kind::kPoints) {
      point_a = pair.world_from_cylinder *
                CylinderSupport(*pair.cylinder,
                                pair.world_from_cylinder.rotation.conjugate() * -axis.normal);
      point_b = point_a - axis.separation * axis.normal;
    }
    points.push_back(
        {0.5 * (point_a + point_b), axis.separation, FeatureId{FeatureType::kEdgeEdge, 0, 0}});
  }
  manifold->normal_world = axis.normal;
  ReduceContactPoints(points.data(), static_cast<int>(points.size()), axis.normal, manifold);
  return manifold->point_count > 0;
}

bool CollideCylinders(const CylinderPair& pair, const Cylinder& other, ContactManifold* manifold) {
  thread_local std::map<std::pair<double, double>, ConvexPolyhedron> prisms;
  auto found = prisms.find({other.radius, other.half_length});
  if (found == prisms.end()) {
    if (prisms.size() > 256) prisms.clear();
    found = prisms
                .emplace(std::make_pair(other.radius, other.half_length),
                         MakeCylinderPolyhedron(other.radius, 2.0 * other.half_length, 64))
                .first;
  }
  return CollideCylinderPolyhedron(pair, found->second, manifold);
}

}  // namespace rigid_body_sim::physics
