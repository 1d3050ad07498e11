// Convex shapes against static triangle meshes.
#include "physics/collision/mesh_collision.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "physics/collision/narrow_phase.h"
#include "physics/collision/polyhedron_collision.h"
#include "physics/collision/polyhedron_manifold.h"
#include "physics/geometry/shape_bounds.h"

namespace rigid_body_sim::physics {
namespace {

using Fold = CollisionMesh::EdgeFold;

// A contact normal within 3 degrees of a triangle's face normal is the
// face's: a box face resting tilted on a triangle may take its own face as
// the reference.
constexpr double kFaceNormalCosine = 0.99863;
// Slack of the edge-region test on cosines.
constexpr double kRegionSlack = 1e-9;
// Contacts whose normals are within this angle of a group's join it.
constexpr double kGroupCosine = 0.9877;  // cos(9 degrees)
// A point of the triangle is at a vertex when it is within this fraction
// of an edge's length of its end.
constexpr double kVertexFraction = 1e-6;
// A face contact's point is over its triangle when no further outside its
// side planes than this fraction of its distance from the mesh's origin
// (at least 1 m): the clip puts points on them, to rounding.
constexpr double kOverTriangleSlack = 1e-9;

// Faces of the prism: the front triangle (0, 1, 2), the back one and the
// three sides, each counter-clockwise from outside.
constexpr int kPrismFaces[5][4] = {
    {0, 1, 2, -1}, {3, 5, 4, -1}, {1, 0, 3, 4}, {2, 1, 4, 5}, {0, 2, 5, 3}};

// The prism's half-edge structure, made once: twins are found by looking
// for the reverse directed edge among those already made.
ConvexPolyhedron MakePrismTopology() {
  ConvexPolyhedron prism;
  prism.vertices.assign(6, Vec3::Zero());
  prism.vertex_half_edge.assign(6, -1);
  struct Directed {
    int from, to, half_edge;
  };
  std::vector<Directed> made;
  std::vector<std::vector<int>> face_half_edges(5);
  for (int f = 0; f < 5; ++f) {
    const int size = kPrismFaces[f][3] < 0 ? 3 : 4;
    for (int k = 0; k < size; ++k) {
      const int from = kPrismFaces[f][k];
      const int to = kPrismFaces[f][(k + 1) % size];
      int half_edge = -1;
      for (const Directed& other : made) {
        if (other.from == to && other.to == from) half_edge = other.half_edge ^ 1;
      }
      if (half_edge < 0) {
        half_edge = static_cast<int>(prism.half_edges.size());
        prism.half_edges.resize(prism.half_edges.size() + 2);
      }
      made.push_back({from, to, half_edge});
      prism.half_edges[half_edge].origin = from;
      prism.half_edges[half_edge].face = f;
      prism.vertex_half_edge[from] = half_edge;
      face_half_edges[f].push_back(half_edge);
    }
    for (int k = 0; k < size; ++k) {
      prism.half_edges[face_half_edges[f][k]].next = face_half_edges[f][(k + 1) % size];
    }
    ConvexPolyhedron::Face face;
    face.first_half_edge = face_half_edges[f][0];
    prism.faces.push_back(face);
  }
  prism.edge_directions.assign(4, Vec3::UnitZ());
  return prism;
}

// Where a contact with normal `normal` (mesh frame, unit) touches the
// triangle at `on_triangle`, decides whether the normal belongs to that
// feature's Voronoi region of the mesh surface. A face owns only its own
// normal; an edge shared with a coplanar or concave neighbour owns none
// besides its faces' (an internal edge of a flat floor must not push
// sideways); a convex edge owns the normals between its two faces, n_f and
// n_g, i.e. n . n_f >= n_f . n_g and n . n_g >= n_f . n_g; a boundary edge
// owns every normal; a vertex owns what its convex or boundary edges do,
// taken as all normals. This is the Voronoi-region test of the contact
// normal against the adjacent face normals (Mirtich 1998, "V-Clip: Fast and
// Robust Polyhedral Collision Detection", ACM TOG 17(3), section 3.1, for
// the regions; Bullet's btInternalEdgeUtility for the use on meshes).
// A two-sided triangle met from behind (`back`) is the surface seen from
// its other side: the face and neighbour normals negate, and a fold convex
// from the front is concave from behind and the other way round.
bool NormalInRegion(const CollisionMesh& mesh, int triangle_index, bool back,
                    const Vec3& on_triangle, const Vec3& normal) {
  const CollisionMesh::Triangle& triangle = mesh.triangles()[triangle_index];
  const double side = back ? -1.0 : 1.0;
  const Vec3 front = side * triangle.normal;
  if (normal.dot(front) >= kFaceNormalCosine) return true;
  int nearest = 0;
  double nearest_distance = std::numeric_limits<double>::infinity();
  double nearest_t = 0.0;
  for (int k = 0; k < 3; ++k) {
    const Vec3& start = mesh.vertices()[triangle.vertices[k]];
    const Vec3 edge = mesh.vertices()[triangle.vertices[(k + 1) % 3]] - start;
    const double t = std::clamp((on_triangle - start).dot(edge) / edge.squaredNorm(), 0.0, 1.0);
    const double distance = (on_triangle - start - t * edge).squaredNorm();
    if (distance < nearest_distance) {
      nearest_distance = distance;
      nearest = k;
      nearest_t = t;
    }
  }
  const auto fold_seen = [&](int k) {
    const Fold fold = triangle.edge_folds.at(k);
    if (!back || fold == Fold::kFlat || fold == Fold::kBoundary) return fold;
    return fold == Fold::kConvex ? Fold::kConcave : Fold::kConvex;
  };
  const auto edge_open = [&](int k) {
    const Fold fold = fold_seen(k);
    return fold == Fold::kBoundary || fold == Fold::kConvex;
  };
  if (nearest_t <= kVertexFraction || nearest_t >= 1.0 - kVertexFraction) {
    const int other = nearest_t <= kVertexFraction ? (nearest + 2) % 3 : (nearest + 1) % 3;
    return edge_open(nearest) || edge_open(other);
  }
  const Fold fold = fold_seen(nearest);
  if (fold == Fold::kBoundary) return true;
  if (fold != Fold::kConvex) return false;
  const Vec3 neighbour = side * triangle.neighbour_normals[nearest];
  const double bound = front.dot(neighbour) - kRegionSlack;
  return normal.dot(front) >= bound && normal.dot(neighbour) >= bound;
}

// One group of contacts with similar normals: its first member's normal
// decides who joins. Each point keeps the normal of the triangle that made
// it, so that the group's normal can be taken over the points that can
// touch within the step (SupportOfGroup).
struct Group {
  Vec3 normal_world = Vec3::UnitZ();
  int first_triangle = 0;
  double deepest = std::numeric_limits<double>::infinity();
  std::vector<ContactPoint> points;
  std::vector<Vec3> point_normals_world;  // unit, one per point
};

// Adds a triangle's manifold to the group whose normal is within
// kGroupCosine of its own, or to a new group.
void AddToGroups(const ContactManifold& manifold, int triangle, std::vector<Group>* groups,
                 int* group_count) {
  Group* group = nullptr;
  for (int g = 0; g < *group_count; ++g) {
    if ((*groups)[g].normal_world.dot(manifold.normal_world) >= kGroupCosine) {
      group = &(*groups)[g];
      break;
    }
  }
  if (group == nullptr) {
    if (*group_count == static_cast<int>(groups->size())) groups->emplace_back();
    group = &(*groups)[(*group_count)++];
    group->normal_world = manifold.normal_world;
    group->first_triangle = triangle;
    group->deepest = std::numeric_limits<double>::infinity();
    group->points.clear();
    group->point_normals_world.clear();
  }
  group->first_triangle = std::min(group->first_triangle, triangle);
  for (int i = 0; i < manifold.point_count; ++i) {
    ContactPoint point = manifold.points[i];
    // Points of different triangles must not share an id: the triangle goes
    // into B's index (the prism's features number below 16).
    point.feature.index_b =
        static_cast<std::uint32_t>(triangle) * 16u + (point.feature.index_b & 15u);
    group->deepest = std::min(group->deepest, point.separation);
    group->points.push_back(point);
    group->point_normals_world.push_back(manifold.normal_world);
  }
}

// The manifold of a group: its normal and at most four points, taken from
// the points that can touch within the step, those whose separation is
// below `reach` (the most the two shapes can close in a step), or from all
// of them when none can. Over a curved mesh a group holds points from
// penetrating to the contact distance apart (5 mm and more); the reduction
// keeps the deepest point and then the points spanning the largest area,
// so it would give the slots to far corners that cannot carry load this
// step and drop a point a fraction of a millimetre away on which the body
// is about to pivot, which then sinks unseen for a step and is met late.
// The normal is the mean of the normals of the triangles under the kept
// candidates, one per point, so that it is the normal of the surface the
// body rests on, not of triangles the contact distance away, which come
// and go as the body rocks. The mean keeps a body lying across a gentle
// ridge (two facets a few degrees apart) from being pushed along one
// facet's normal and then the other's as its deepest point changes side.
// Reduction: ReduceContactPoints (deepest point, then largest support
// polygon); the restriction to points within reach is the speculative
// contact's bound (Catto 2013, "Continuous Collision", GDC, speculative
// contacts: a point further than the step's closing distance cannot touch
// within the step).
void SupportOfGroup(const Group& group, double reach, ContactManifold* manifold) {
  thread_local std::vector<ContactPoint> candidates;
  candidates.clear();
  Vec3 normal_sum = Vec3::Zero();
  const double limit = group.deepest < reach ? reach : std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < group.points.size(); ++i) {
    if (group.points[i].separation > limit) continue;
    candidates.push_back(group.points[i]);
    normal_sum += group.point_normals_world[i];
  }
  ReduceContactPoints(candidates.data(), static_cast<int>(candidates.size()),
                      normal_sum.normalized(), manifold);
}

// min over the convex shape of n . x, for a unit n in the shape's frame:
// -r for a sphere, -h |n_z| - r sqrt(1 - n_z^2) for a cylinder (its support,
// Ericson 2005, section 5.1), the support vertex's for a polyhedron.
double LowestAlong(const ShapeGeometry& convex, const Vec3& normal_shape) {
  if (const auto* sphere = std::get_if<Sphere>(&convex)) return -sphere->radius;
  if (const auto* cylinder = std::get_if<Cylinder>(&convex)) {
    const double along = normal_shape.z();
    return -cylinder->half_length * std::abs(along) -
           cylinder->radius * std::sqrt(std::max(0.0, 1.0 - along * along));
  }
  const auto& polyhedron = *std::get<std::shared_ptr<const ConvexPolyhedron>>(convex);
  return normal_shape.dot(polyhedron.vertices[polyhedron.SupportVertex(-normal_shape)]);
}

// The centre of a convex shape in its own frame.
Vec3 ShapeCenter(const ShapeGeometry& convex) {
  if (const auto* polyhedron = std::get_if<std::shared_ptr<const ConvexPolyhedron>>(&convex)) {
    return (*polyhedron)->centroid;
  }
  return Vec3::Zero();
}

}  // namespace

// Sets the prism's vertices (the front triangle and its copy `depth` behind
// it) and its face planes on the shared topology.
void MakeTrianglePrism(const std::array<Vec3, 3>& front_ccw, double depth,
                       ConvexPolyhedron* prism) {
  static const ConvexPolyhedron kTopology = MakePrismTopology();
  if (prism->half_edges.size() != kTopology.half_edges.size()) *prism = kTopology;
  const Vec3 normal = (front_ccw[1] - front_ccw[0]).cross(front_ccw[2] - front_ccw[0]).normalized();
  for (int k = 0; k < 3; ++k) {
    prism->vertices[k] = front_ccw[k];
    prism->vertices[k + 3] = front_ccw[k] - depth * normal;
  }
  prism->faces[0].normal = normal;
  prism->faces[1].normal = -normal;
  for (int k = 0; k < 3; ++k) {
    const Vec3 edge = front_ccw[(k + 1) % 3] - front_ccw[k];
    prism->faces[2 + k].normal = edge.cross(normal).normalized();
    prism->edge_directions[k] = edge.normalized();
  }
  prism->edge_directions[3] = normal;
  for (int f = 0; f < 5; ++f) {
    prism->faces[f].offset = prism->faces[f].normal.dot(prism->vertices[kPrismFaces[f][0]]);
  }
  prism->centroid = Vec3::Zero();
  for (const Vec3& vertex : prism->vertices) prism->centroid += vertex / 6.0;
}

// The triangles whose boxes come within the contact distance of the convex
// shape's box (CollisionMesh::QueryBox) are each taken as the prism behind
// their face, extruded away from the shape by more than the shape's
// diameter, so that the prism's back never decides a contact. A triangle of
// a closed component collides on its front (outer) side only: one whose
// plane has the shape's centre behind it is skipped (the underside of a
// bin's floor must not hold up a box resting on the floor's top, 5 mm
// above). A two-sided triangle (of an open component: a sheet, a terrain)
// collides on the side of its plane the shape's centre is on: from behind
// it is taken reversed, its winding, prism and edge regions those of the
// other side, as Bullet's and Gazebo's triangle meshes collide from both
// sides. A triangle whose plane the shape lies in front of by the contact
// distance (its support point along -n, which also bounds the gap) is
// skipped too.
// Each prism is collided with the convex routines of the narrow phase
// (separating axes and clipping for polyhedra, exact for spheres and
// cylinders), and the normal is checked against the Voronoi region of the
// touched feature (NormalInRegion), so that a body sliding over the
// internal edges of a flat floor never meets a side of a prism. A manifold
// whose normal lies outside the region is replaced by the contact with the
// triangle's face alone, along its normal, from the part of the shape over
// the triangle (TriangleQuery::FaceContact). Dropping it, for the
// neighbouring face's prism to report the contact with that face's normal,
// holds only while the shape overlaps the triangle sideways by more than it
// sinks into the neighbour; a corner sunk deeper than its distance to the
// edges of the small triangles it is over met every prism on a side axis,
// and the mesh then reported no contact at all, and a gap, to the narrow
// phase and to the time-of-impact search. Moving the points onto the face,
// as Bullet's btAdjustInternalEdgeContacts does, needs points on the convex
// shape, which a manifold of shapes still apart does not have; the face
// contact makes its own. The manifolds are then grouped by
// normal; the kContactSlots groups with the deepest points are kept, the
// deepest first and the others in the order of their first triangle (so a
// group keeps its slot from step to step), and each is reduced to four
// points among those the shapes can reach within the step
// (SupportOfGroup).
namespace {

// The triangles near a convex shape and how each one is collided with it.
class TriangleQuery {
 public:
  // A candidate triangle, a lower bound on its separation from the shape,
  // and whether the shape meets it from behind (a two-sided triangle).
  struct Candidate {
    int triangle = 0;
    double bound = 0.0;  // m
    bool back = false;
  };

  // The triangles whose boxes come within the contact distance of the
  // shape's box, less those seen from behind, into `candidates`; `gap`
  // (m) becomes a lower bound on the distance to the others.
  TriangleQuery(const ConvexMeshPair& pair, std::vector<Candidate>* candidates, double* gap)
      : pair_(pair),
        mesh_(*pair.mesh),
        mesh_from_convex_(pair.world_from_mesh.Inverse() * pair.world_from_convex),
        world_from_mesh_rotation_(pair.world_from_mesh.rotation.toRotationMatrix()),
        polyhedron_(std::get_if<std::shared_ptr<const ConvexPolyhedron>>(pair.convex)),
        prism_geometry_(std::shared_ptr<const ConvexPolyhedron>(std::shared_ptr<void>(), &prism_)) {
    thread_local std::vector<int> found;
    const Aabb box = ShapeAabb(*pair.convex, mesh_from_convex_).Fattened(pair.contact_distance);
    found.clear();
    mesh_.QueryBox(box.min, box.max, &found);
    // Apart along a box axis by the contact distance: at least that far.
    *gap = pair.contact_distance;
    candidates->clear();
    if (found.empty()) return;
    *gap = std::numeric_limits<double>::infinity();
    const Vec3 local_center = ShapeCenter(*pair.convex);
    const Vec3 center_mesh = mesh_from_convex_ * local_center;
    depth_ = 2.0 * ShapeBoundingRadius(*pair.convex, local_center) + pair.contact_distance;
    convex_from_mesh_ = mesh_from_convex_.rotation.conjugate().toRotationMatrix();
    for (const int t : found) {
      const CollisionMesh::Triangle& triangle = mesh_.triangles()[t];
      const double offset = triangle.normal.dot(mesh_.vertices()[triangle.vertices[0]]);
      // A one-sided triangle seen from behind: no contact.
      const bool back = triangle.normal.dot(center_mesh) < offset;
      if (back && !triangle.two_sided) continue;
      const double side = back ? -1.0 : 1.0;
      const Vec3 normal = side * triangle.normal;
      const double plane = side * offset;
      // In front of the plane by the contact distance (the plane's distance
      // bounds the triangle's): no contact.
      const double bound = normal.dot(mesh_from_convex_.translation) +
                           LowestAlong(*pair.convex, convex_from_mesh_ * normal) - plane;
      if (bound >= pair.contact_distance) {
        *gap = std::min(*gap, bound);
        continue;
      }
      const double apart = FaceOfConvexSeparation(triangle, normal);
      if (apart > pair.contact_distance) {
        *gap = std::min(*gap, apart);
        continue;
      }
      candidates->push_back({t, bound, back});
    }
  }

  // The manifold of the candidate's prism, on the side the shape meets it,
  // true when it has points whose normal lies in the touched feature's
  // region, or else points of the face contact (FaceContact); with no
  // points `gap` is lowered to a lower bound on the separation.
  bool Collide(const Candidate& candidate, ContactManifold* manifold, double* gap) {
    const CollisionMesh::Triangle& triangle = mesh_.triangles()[candidate.triangle];
    // Reversed, counter-clockwise seen from behind.
    const int second = candidate.back ? 2 : 1;
    MakeTrianglePrism(
        {mesh_.vertices()[triangle.vertices[0]], mesh_.vertices()[triangle.vertices[second]],
         mesh_.vertices()[triangle.vertices[3 - second]]},
        depth_, &prism_);
    CollideStats stats;
    if (!physics::Collide({pair_.convex, pair_.world_from_convex, &prism_geometry_,
                           pair_.world_from_mesh, pair_.contact_distance},
                          nullptr, manifold, &stats)) {
      *gap = std::min(*gap, stats.gap);
      return false;
    }
    int deepest = 0;
    for (int i = 1; i < manifold->point_count; ++i) {
      if (manifold->points[i].separation < manifold->points[deepest].separation) deepest = i;
    }
    const ContactPoint& point = manifold->points[deepest];
    const Vec3 on_triangle =
        pair_.world_from_mesh.Inverse() *
        (point.position_world - 0.5 * point.separation * manifold->normal_world);
    const Vec3 normal_mesh = world_from_mesh_rotation_.transpose() * manifold->normal_world;
    if (NormalInRegion(mesh_, candidate.triangle, candidate.back, on_triangle, normal_mesh)) {
      return true;
    }
    if (FaceContact(manifold)) return true;
    // Nothing over the face within the contact distance: the separation
    // along the face normal bounds the distance to the triangle.
    *gap = std::min(*gap, candidate.bound);
    return false;
  }

 private:
  // The largest separation of the triangle's prism (front vertices v_k,
  // normal n towards the shape, extruded by the depth d along -n) from the
  // faces of a polyhedral shape, the first of the separating-axis test's
  // axes. The shape lies at u.x <= c below a face (u outward, plane
  // u.x = c), and the prism's least extent along u is that of its six
  // vertices, min_k u.v_k + min(0, -d u.n), so the gap along u is
  // s_u = min_k u.v_k + min(0, -d u.n) - c (Gottschalk, Lin and Manocha
  // 1996, "OBBTree", section 4: a polytope projects on an axis to the
  // interval of its vertices). One face beyond the contact distance settles
  // the pair before the prism is built; -infinity for a shape that is not a
  // polyhedron.
  double FaceOfConvexSeparation(const CollisionMesh::Triangle& triangle,
                                const Vec3& normal_mesh) const {
    if (polyhedron_ == nullptr) return -std::numeric_limits<double>::infinity();
    std::array<Vec3, 3> vertices;
    for (int k = 0; k < 3; ++k) {
      vertices[k] = Multiply(convex_from_mesh_, mesh_.vertices()[triangle.vertices[k]] -
                                                    mesh_from_convex_.translation);
    }
    const Vec3 normal = Multiply(convex_from_mesh_, normal_mesh);
    double largest = -std::numeric_limits<double>::infinity();
    for (const ConvexPolyhedron::Face& face : (*polyhedron_)->faces) {
      const double least = std::min({face.normal.dot(vertices[0]), face.normal.dot(vertices[1]),
                                     face.normal.dot(vertices[2])}) +
                           std::min(0.0, -depth_ * face.normal.dot(normal));
      largest = std::max(largest, least - face.offset);
    }
    return largest;
  }

  // The contact of the shape with the face of the prism last made (its
  // front triangle, normal n, offset d) alone, along n, for when the
  // prism's contact normal lies outside the touched feature's Voronoi
  // region (a prism side or an edge pair across an internal edge, which is
  // no surface of the mesh). Such a contact used to be dropped for the
  // neighbour's prism to report with its own face normal; but a shape that
  // sinks into a triangle deeper than its sideways distance to the
  // triangle's edges (a box corner landing at 3 m/s sinks 1.2 cm in a step,
  // more than the 1.3 cm inradius of a 4.5 cm cell) makes every prism's
  // side axis win, every contact was dropped, and the body fell through.
  // The separating axis is instead restricted to the one normal the face's
  // region always owns, n (Mirtich 1998, "V-Clip", section 3.1: a face owns
  // its normal), the contact the mesh seen as a height field over the
  // triangle has. A polyhedron's incident face (the face most anti-parallel
  // to n) is clipped to the triangle's side planes m_k = e_k x n (Sutherland
  // and Hodgman 1974, "Reentrant Polygon Clipping", CACM 17(1); the face
  // contact of BuildFaceContact), each clipped point p a contact of
  // separation s = n . p - d below the contact distance. A sphere or a
  // cylinder is collided with the plane n . x = d as a half-space (its
  // support along -n, Ericson 2005, section 5.1). Either way only points
  // over the triangle are kept, m_k . p <= m_k . v_k for all k, so each
  // triangle answers for the part of the surface it covers and no contact
  // comes from its plane extended over the neighbours.
  bool FaceContact(ContactManifold* manifold) const {
    manifold->point_count = 0;
    if (const auto* polyhedron =
            std::get_if<std::shared_ptr<const ConvexPolyhedron>>(pair_.convex)) {
      FaceContactInput input;
      input.reference = &prism_;
      input.world_from_reference = pair_.world_from_mesh;
      input.reference_face = 0;
      input.incident = polyhedron->get();
      input.world_from_incident = pair_.world_from_convex;
      input.reference_is_a = false;
      input.contact_distance = pair_.contact_distance;
      if (!BuildFaceContact(input, manifold)) return false;
    } else {
      static const ShapeGeometry kPlane = HalfSpace{};
      Pose world_from_plane;
      world_from_plane.translation = pair_.world_from_mesh * prism_.vertices[0];
      world_from_plane.rotation = pair_.world_from_mesh.rotation *
                                  Quat::FromTwoVectors(Vec3::UnitZ(), prism_.faces[0].normal);
      if (!physics::Collide({pair_.convex, pair_.world_from_convex, &kPlane, world_from_plane,
                             pair_.contact_distance},
                            nullptr, manifold)) {
        return false;
      }
    }
    // BuildFaceContact falls back on the support vertex when the clip keeps
    // nothing, and the half-space has no edges: points off the triangle go.
    const Pose mesh_from_world = pair_.world_from_mesh.Inverse();
    int kept = 0;
    for (int i = 0; i < manifold->point_count; ++i) {
      const Vec3 point = mesh_from_world * manifold->points[i].position_world;
      const double slack = kOverTriangleSlack * std::max(1.0, point.cwiseAbs().maxCoeff());
      bool over = true;
      for (int k = 0; k < 3; ++k) {
        const ConvexPolyhedron::Face& side = prism_.faces[2 + k];
        over = over && side.normal.dot(point) - side.offset <= slack;
      }
      if (over) manifold->points[kept++] = manifold->points[i];
    }
    manifold->point_count = kept;
    return kept > 0;
  }

  const ConvexMeshPair& pair_;
  const CollisionMesh& mesh_;
  const Pose mesh_from_convex_;
  const Mat3 world_from_mesh_rotation_;
  const std::shared_ptr<const ConvexPolyhedron>* polyhedron_;  // null for other shapes
  Mat3 convex_from_mesh_;
  double depth_ = 0.0;  // m, of the prisms
  ConvexPolyhedron prism_;
  // Lends prism_ to the narrow phase; owns nothing.
  const ShapeGeometry prism_geometry_;
};

}  // namespace

void CollideConvexMesh(const ConvexMeshPair& pair, MeshContacts* contacts) {
  thread_local std::vector<TriangleQuery::Candidate> candidates;
  thread_local std::vector<Group> groups;
  thread_local std::vector<Group*> kept;
  for (ContactManifold& manifold : contacts->manifolds) manifold.point_count = 0;
  double gap = 0.0;
  TriangleQuery query(pair, &candidates, &gap);
  int group_count = 0;
  for (const TriangleQuery::Candidate& candidate : candidates) {
    ContactManifold manifold;
    if (query.Collide(candidate, &manifold, &gap)) {
      AddToGroups(manifold, candidate.triangle, &groups, &group_count);
    }
  }
  contacts->gap = gap;
  if (group_count == 0) return;
  kept.clear();
  for (int g = 0; g < group_count; ++g) kept.push_back(&groups[g]);
  if (group_count > StaticMesh::kContactSlots) {
    std::partial_sort(kept.begin(), kept.begin() + StaticMesh::kContactSlots, kept.end(),
                      [](const Group* x, const Group* y) { return x->deepest < y->deepest; });
    kept.resize(StaticMesh::kContactSlots);
  }
  // The deepest group first, so that slot 0 holds the least separation of
  // all (what CollideConvexMeshDeepest finds along the time-of-impact
  // search); the others by their first triangle.
  std::iter_swap(kept.begin(),
                 std::min_element(kept.begin(), kept.end(), [](const Group* x, const Group* y) {
                   return x->deepest < y->deepest;
                 }));
  std::sort(kept.begin() + 1, kept.end(),
            [](const Group* x, const Group* y) { return x->first_triangle < y->first_triangle; });
  for (std::size_t s = 0; s < kept.size(); ++s) {
    SupportOfGroup(*kept[s], pair.reach, &contacts->manifolds[s]);
  }
  contacts->gap = -std::numeric_limits<double>::infinity();
}

// The candidates in order of their plane bound; a triangle whose bound is
// not below the deepest separation found so far cannot be deeper (the
// separation along the face normal is one of the separating-axis test's,
// and the test takes the largest), so the walk stops there.
bool CollideConvexMeshDeepest(const ConvexMeshPair& pair, ContactManifold* manifold, double* gap) {
  thread_local std::vector<TriangleQuery::Candidate> candidates;
  manifold->point_count = 0;
  TriangleQuery query(pair, &candidates, gap);
  std::sort(candidates.begin(), candidates.end(),
            [](const TriangleQuery::Candidate& x, const TriangleQuery::Candidate& y) {
              return x.bound < y.bound;
            });
  double deepest = std::numeric_limits<double>::infinity();
  for (const TriangleQuery::Candidate& candidate : candidates) {
    if (candidate.bound >= deepest) break;
    ContactManifold found;
    if (!query.Collide(candidate, &found, gap)) continue;
    double least = std::numeric_limits<double>::infinity();
    for (int i = 0; i < found.point_count; ++i) least = std::min(least, found.points[i].separation);
    if (least < deepest) {
      deepest = least;
      *manifold = found;
    }
  }
  if (manifold->point_count > 0) *gap = -std::numeric_limits<double>::infinity();
  return manifold->point_count > 0;
}

}  // namespace rigid_body_sim::physics
