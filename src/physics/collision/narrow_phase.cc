#include "physics/collision/narrow_phase.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <utility>
#include <variant>
#include <vector>

#include "physics/collision/mesh_collision.h"

namespace rigid_body_sim::physics {
namespace {

using PolyhedronPtr = std::shared_ptr<const ConvexPolyhedron>;

// Variant order (Sphere, polyhedron, HalfSpace, Cylinder, StaticMesh) is the dispatch order: the
// pair is swapped so that A has the lower index, and the result swapped back.
constexpr std::size_t kSphereIndex = 0;
constexpr std::size_t kPolyhedronIndex = 1;
constexpr std::size_t kHalfSpaceIndex = 2;
constexpr std::size_t kCylinderIndex = 3;
constexpr std::size_t kStaticMeshIndex = 4;
constexpr std::size_t kShapeKinds = 5;

// A single-point manifold.
bool SinglePoint(const Vec3& normal_world, const Vec3& position_world, double separation,
                 FeatureId feature, ContactManifold* manifold) {
  manifold->normal_world = normal_world;
  manifold->points[0] = {position_world, separation, feature};
  manifold->point_count = 1;
  return true;
}

// Two spheres: n = (c_a - c_b) / |c_a - c_b|, s = |c_a - c_b| - r_a - r_b,
// the point midway between the surface points c_a - r_a n and c_b + r_b n.
// Concentric spheres get an arbitrary normal (+z).
bool CollideSpheres(const Sphere& a, const Vec3& centre_a, const Sphere& b, const Vec3& centre_b,
                    double contact_distance, ContactManifold* manifold) {
  const Vec3 delta = centre_a - centre_b;
  const double distance = delta.norm();
  const double separation = distance - a.radius - b.radius;
  if (!(separation < contact_distance)) return false;
  const Vec3 normal = distance > 0.0 ? Vec3(delta / distance) : Vec3::UnitZ();
  const Vec3 position = 0.5 * ((centre_a - a.radius * normal) + (centre_b + b.radius * normal));
  return SinglePoint(normal, position, separation, FeatureId{}, manifold);
}

// Closest point of convex face `face` to x (shape frame): the projection
// onto the face plane when it lies inside every edge, otherwise the closest
// point on the nearest boundary edge.
Vec3 ClosestPointOnFace(const ConvexPolyhedron& polyhedron, int face, const Vec3& x) {
  const ConvexPolyhedron::Face& plane = polyhedron.faces[face];
  const Vec3 projection = x - (plane.normal.dot(x) - plane.offset) * plane.normal;
  bool inside = true;
  Vec3 best = projection;
  double best_squared = std::numeric_limits<double>::infinity();
  const int first = plane.first_half_edge;
  int h = first;
  do {
    const int next = polyhedron.half_edges[h].next;
    const Vec3& start = polyhedron.vertices[polyhedron.half_edges[h].origin];
    const Vec3& end = polyhedron.vertices[polyhedron.half_edges[next].origin];
    const Vec3 edge = end - start;
    if (edge.cross(plane.normal).dot(projection - start) > 0.0) inside = false;
    const double t = std::clamp((x - start).dot(edge) / edge.squaredNorm(), 0.0, 1.0);
    const Vec3 on_edge = start + t * edge;
    const double distance_squared = (x - on_edge).squaredNorm();
    if (distance_squared < best_squared) {
      best_squared = distance_squared;
      best = on_edge;
    }
    h = next;
  } while (h != first);
  return inside ? projection : best;
}

// Sphere (A) against polyhedron (B), in B's frame with centre c. Let
// s_max = max_f (n_f.c - d_f). If s_max <= 0 the centre is inside and the
// face of least penetration gives n = n_f and surface point c - s_max n_f.
// Otherwise the closest point q of the polyhedron lies on a face that sees c
// (n_f.c > d_f); the nearest point over those faces is exact, and
// n = (c - q) / |c - q|. In both cases s = (signed distance) - r.
bool CollideSpherePolyhedron(const Sphere& sphere, const Vec3& centre_world,
                             const ConvexPolyhedron& polyhedron, const Pose& world_from_b,
                             double contact_distance, ContactManifold* manifold) {
  const Vec3 centre = world_from_b.Inverse() * centre_world;
  int least_face = 0;
  double least_distance = -std::numeric_limits<double>::infinity();
  for (int f = 0; f < static_cast<int>(polyhedron.faces.size()); ++f) {
    const double distance = polyhedron.faces[f].normal.dot(centre) - polyhedron.faces[f].offset;
    if (distance > least_distance) {
      least_distance = distance;
      least_face = f;
    }
  }
  // The distance to the polyhedron is at least the largest plane distance.
  if (!(least_distance - sphere.radius < contact_distance)) return false;
  Vec3 normal = Vec3::UnitZ();
  Vec3 surface = centre;
  double signed_distance = 0.0;
  if (least_distance <= 0.0) {
    normal = polyhedron.faces[least_face].normal;
    surface = centre - least_distance * normal;
    signed_distance = least_distance;
  } else {
    double best_squared = std::numeric_limits<double>::infinity();
    for (int f = 0; f < static_cast<int>(polyhedron.faces.size()); ++f) {
      if (!(polyhedron.faces[f].normal.dot(centre) - polyhedron.faces[f].offset > 0.0)) continue;
      const Vec3 point = ClosestPointOnFace(polyhedron, f, centre);
      const double distance_squared = (centre - point).squaredNorm();
      if (distance_squared < best_squared) {
        best_squared = distance_squared;
        surface = point;
      }
    }
    signed_distance = std::sqrt(best_squared);
    normal = (centre - surface) / signed_distance;
  }
  const double separation = signed_distance - sphere.radius;
  if (!(separation < contact_distance)) return false;
  const Vec3 normal_world = world_from_b.rotation * normal;
  const Vec3 position =
      0.5 * ((world_from_b * surface) + (centre_world - sphere.radius * normal_world));
  return SinglePoint(normal_world, position, separation, FeatureId{}, manifold);
}

// Sphere (A) against the half-space z <= 0 of B: n = B's z axis,
// s = n.(c - t_b) - r, point midway between c - r n and the plane.
bool CollideSphereHalfSpace(const Sphere& sphere, const Vec3& centre, const Pose& world_from_b,
                            double contact_distance, ContactManifold* manifold) {
  const Vec3 normal = world_from_b.rotation * Vec3::UnitZ();
  const double height = normal.dot(centre - world_from_b.translation);
  const double separation = height - sphere.radius;
  if (!(separation < contact_distance)) return false;
  const Vec3 position = centre - (sphere.radius + 0.5 * separation) * normal;
  return SinglePoint(normal, position, separation, FeatureId{}, manifold);
}

// Polyhedron (A) against the half-space z <= 0 of B: every vertex with
// s = n.(v - t_b) below the contact distance is a vertex/face contact,
// reduced to four points like a face manifold.
bool CollidePolyhedronHalfSpace(const ConvexPolyhedron& polyhedron, const Pose& world_from_a,
                                const Pose& world_from_b, double contact_distance,
                                ContactManifold* manifold) {
  thread_local std::vector<ContactPoint> kept;
  const Vec3 normal = world_from_b.rotation * Vec3::UnitZ();
  const Vec3 normal_in_a = world_from_a.rotation.conjugate() * normal;
  const double plane_height = normal.dot(world_from_b.translation);
  // s = n.(R v + t) - h = (R^T n).v + (n.t - h): no vertex is moved to the
  // world frame unless it is kept.
  const double height_of_a = normal.dot(world_from_a.translation) - plane_height;
  const Vec3& deepest = polyhedron.vertices[polyhedron.SupportVertex(-normal_in_a)];
  if (!(normal_in_a.dot(deepest) + height_of_a < contact_distance)) return false;
  kept.clear();
  for (int v = 0; v < static_cast<int>(polyhedron.vertices.size()); ++v) {
    const double separation = normal_in_a.dot(polyhedron.vertices[v]) + height_of_a;
    if (separation < contact_distance) {
      const Vec3 vertex = world_from_a * polyhedron.vertices[v];
      kept.push_back({vertex - 0.5 * separation * normal, separation,
                      FeatureId{FeatureType::kVertexFace, static_cast<std::uint16_t>(v), 0}});
    }
  }
  ReduceContactPoints(kept.data(), static_cast<int>(kept.size()), normal, manifold);
  return manifold->point_count > 0;
}

// A convex shape (A) against slot `mesh.slot` of a static mesh (B): the
// slot's group of contacts (CollideConvexMesh). Without `stats` (the
// time-of-impact search's and FindOverlaps' calls, which want the least
// separation) slot 0 holds the deepest triangle contact of any group and
// the other slots nothing (CollideConvexMeshDeepest).
bool CollideWithMesh(const ShapeGeometry& convex, const Pose& world_from_a, const StaticMesh& mesh,
                     const Pose& world_from_b, double contact_distance, ContactManifold* manifold,
                     CollideStats* stats) {
  const ConvexMeshPair pair{&convex, world_from_a, mesh.mesh.get(), world_from_b, contact_distance};
  if (stats == nullptr) {
    double gap = 0.0;
    return mesh.slot == 0 && CollideConvexMeshDeepest(pair, manifold, &gap);
  }
  thread_local MeshContacts contacts;
  CollideConvexMesh(pair, &contacts);
  *manifold = contacts.manifolds[mesh.slot];
  stats->gap = contacts.gap;
  return manifold->point_count > 0;
}

// The manifold of (B, A) turned into that of (A, B): the normal flips and
// the feature roles swap.
void SwapRoles(ContactManifold* manifold) {
  manifold->normal_world = -manifold->normal_world;
  for (int i = 0; i < manifold->point_count; ++i) {
    FeatureId& feature = manifold->points[i].feature;
    std::swap(feature.index_a, feature.index_b);
    if (feature.type == FeatureType::kVertexFace) {
      feature.type = FeatureType::kFaceVertex;
    } else if (feature.type == FeatureType::kFaceVertex) {
      feature.type = FeatureType::kVertexFace;
    }
  }
}

}  // namespace

bool Collide(const CollideInput& input, SeparatingWitness* witness, ContactManifold* manifold,
             CollideStats* stats) {
  assert(input.a != nullptr && input.b != nullptr && manifold != nullptr);
  if (stats != nullptr) *stats = CollideStats{};
  manifold->point_count = 0;
  const bool swapped = input.a->index() > input.b->index();
  const ShapeGeometry& a = swapped ? *input.b : *input.a;
  const ShapeGeometry& b = swapped ? *input.a : *input.b;
  const Pose& world_from_a = swapped ? input.world_from_b : input.world_from_a;
  const Pose& world_from_b = swapped ? input.world_from_a : input.world_from_b;
  const double contact_distance = input.contact_distance;

  // The cylinder routines take the cylinder as A; with the dispatch order
  // it arrives as B, so those pairs swap once more.
  bool touching = false;
  bool cylinder_swapped = false;
  const Cylinder* cylinder_b = std::get_if<Cylinder>(&b);
  const CylinderPair cylinder_pair{cylinder_b, world_from_b, world_from_a, contact_distance};
  switch (a.index() * kShapeKinds + b.index()) {
    case kSphereIndex* kShapeKinds + kSphereIndex:
      touching = CollideSpheres(std::get<Sphere>(a), world_from_a.translation, std::get<Sphere>(b),
                                world_from_b.translation, contact_distance, manifold);
      break;
    case kSphereIndex* kShapeKinds + kPolyhedronIndex:
      touching = CollideSpherePolyhedron(std::get<Sphere>(a), world_from_a.translation,
                                         *std::get<PolyhedronPtr>(b), world_from_b,
                                         contact_distance, manifold);
      break;
    case kSphereIndex* kShapeKinds + kHalfSpaceIndex:
      touching = CollideSphereHalfSpace(std::get<Sphere>(a), world_from_a.translation, world_from_b,
                                        contact_distance, manifold);
      break;
    case kPolyhedronIndex* kShapeKinds + kPolyhedronIndex:
      // Never swapped, so the witness keeps the caller's A/B roles.
      touching =
          CollidePolyhedra({std::get<PolyhedronPtr>(a).get(), world_from_a,
                            std::get<PolyhedronPtr>(b).get(), world_from_b, contact_distance},
                           witness, manifold, stats);
      break;
    case kPolyhedronIndex* kShapeKinds + kHalfSpaceIndex:
      touching = CollidePolyhedronHalfSpace(*std::get<PolyhedronPtr>(a), world_from_a, world_from_b,
                                            contact_distance, manifold);
      break;
    case kSphereIndex* kShapeKinds + kCylinderIndex:
      touching = CollideCylinderSphere(cylinder_pair, std::get<Sphere>(a), manifold);
      cylinder_swapped = true;
      break;
    case kPolyhedronIndex* kShapeKinds + kCylinderIndex:
      touching = CollideCylinderPolyhedron(cylinder_pair, *std::get<PolyhedronPtr>(a), manifold);
      cylinder_swapped = true;
      break;
    case kHalfSpaceIndex* kShapeKinds + kCylinderIndex:
      touching = CollideCylinderHalfSpace(cylinder_pair, manifold);
      cylinder_swapped = true;
      break;
    case kCylinderIndex* kShapeKinds + kCylinderIndex:
      touching =
          CollideCylinders({&std::get<Cylinder>(a), world_from_a, world_from_b, contact_distance},
                           *cylinder_b, manifold);
      break;
    case kSphereIndex* kShapeKinds + kStaticMeshIndex:
    case kPolyhedronIndex* kShapeKinds + kStaticMeshIndex:
    case kCylinderIndex* kShapeKinds + kStaticMeshIndex:
      touching = CollideWithMesh(a, world_from_a, std::get<StaticMesh>(b), world_from_b,
                                 contact_distance, manifold, stats);
      break;
    default:
      assert(false && "half-spaces and static meshes are static and never meet each other");
      break;
  }
  if (!touching) {
    manifold->point_count = 0;
    return false;
  }
  if (swapped != cylinder_swapped) SwapRoles(manifold);
  return true;
}

double Gap(const CollideInput& input) {
  ContactManifold manifold;
  double gap = input.contact_distance;
  if (Collide(input, nullptr, &manifold)) {
    for (int i = 0; i < manifold.point_count; ++i)
      gap = std::min(gap, manifold.points[i].separation);
  }
  return gap;
}

}  // namespace rigid_body_sim::physics
