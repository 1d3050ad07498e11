// Building a convex polyhedron from polygons: checks, coplanar merging and
// the half-edge structure (MakeConvexPolyhedron).
#include "rigid_body_sim/physics/convex_polyhedron.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace rigid_body_sim::physics {
namespace {

// Tolerances relative to the bounding-box diagonal of the input (`scale`):
// Neighbouring faces whose vertices all lie within this distance of each
// other's plane are one face. Multiplied by the face size this is an angle
// tolerance of about 1e-9 rad, far below any real dihedral angle.
constexpr double kCoplanarTolerance = 1e-9;
// A face whose vertices leave its Newell plane by more than this is refused
// as non-planar, and a vertex further than this in front of any face plane
// makes the input non-convex. Looser than kCoplanarTolerance so hulls from
// qhull, which merges facets with its own rounding bound, are accepted.
constexpr double kPlaneTolerance = 1e-7;
// Twice the area of a face below kAreaTolerance * scale^2 is degenerate.
constexpr double kAreaTolerance = 1e-12;
// Edge directions whose cross product (sine of the angle) is below this are
// the same direction; the separating-axis test needs each direction once.
constexpr double kEdgeDirectionTolerance = 1e-7;

using Loop = std::vector<int>;

// Each directed edge u->v (EdgeKey) and the face it bounds.
using EdgeFaces = std::unordered_map<std::int64_t, int>;

// Newell's method: n = sum over edges (y_i - y_j)(z_i + z_j), ... which is
// sum v_i x v_j = 2 A n for a planar polygon and the best-fit normal of a
// slightly non-planar one (Newell, via Sutherland et al. 1974). Coordinates
// are taken relative to the polygon mean to avoid cancellation.
Vec3 NewellNormal(const std::vector<Vec3>& vertices, const Loop& loop) {
  Vec3 mean = Vec3::Zero();
  for (int v : loop) mean += vertices[v];
  mean /= static_cast<double>(loop.size());
  Vec3 normal = Vec3::Zero();
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vec3 a = vertices[loop[i]] - mean;
    const Vec3 b = vertices[loop[(i + 1) % loop.size()]] - mean;
    normal.x() += (a.y() - b.y()) * (a.z() + b.z());
    normal.y() += (a.z() - b.z()) * (a.x() + b.x());
    normal.z() += (a.x() - b.x()) * (a.y() + b.y());
  }
  return normal;
}

struct Plane {
  Vec3 normal = Vec3::Zero();  // unit
  double offset = 0.0;         // m
};

Plane PlaneOfLoop(const std::vector<Vec3>& vertices, const Loop& loop) {
  Plane plane;
  plane.normal = NewellNormal(vertices, loop).normalized();
  Vec3 mean = Vec3::Zero();
  for (int v : loop) mean += vertices[v];
  plane.offset = plane.normal.dot(mean / static_cast<double>(loop.size()));
  return plane;
}

double MaxDistanceToPlane(const std::vector<Vec3>& vertices, const Loop& loop, const Plane& plane) {
  double distance = 0.0;
  for (int v : loop) {
    distance = std::max(distance, std::abs(plane.normal.dot(vertices[v]) - plane.offset));
  }
  return distance;
}

std::int64_t EdgeKey(int from, int to, int vertex_count) {
  return static_cast<std::int64_t>(from) * vertex_count + to;
}

int FindRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

std::string Describe(const Vec3& v) {
  std::ostringstream out;
  out.precision(9);
  out << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return out.str();
}

Result<ConvexPolyhedron> Fail(const std::string& message) {
  return Result<ConvexPolyhedron>::Error("convex polyhedron: " + message);
}

// Checks the input polygons and returns the bounding-box diagonal.
Result<double> CheckInput(const std::vector<Vec3>& vertices, const std::vector<Loop>& faces) {
  if (vertices.size() < 4) {
    return Result<double>::Error("needs at least 4 vertices, got " +
                                 std::to_string(vertices.size()));
  }
  if (faces.size() < 4) {
    return Result<double>::Error("needs at least 4 faces, got " + std::to_string(faces.size()));
  }
  const int vertex_count = static_cast<int>(vertices.size());
  Vec3 lower = vertices[0];
  Vec3 upper = vertices[0];
  for (int i = 0; i < vertex_count; ++i) {
    if (!IsFinite(vertices[i])) {
      return Result<double>::Error("vertex " + std::to_string(i) + " is not finite");
    }
    lower = lower.cwiseMin(vertices[i]);
    upper = upper.cwiseMax(vertices[i]);
  }
  const double scale = (upper - lower).norm();
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    return Result<double>::Error("vertices span no finite, non-zero extent");
  }
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const Loop& face = faces[f];
    if (face.size() < 3) {
      return Result<double>::Error("face " + std::to_string(f) + " has " +
                                   std::to_string(face.size()) + " vertices, needs at least 3");
    }
    for (int v : face) {
      if (v < 0 || v >= vertex_count) {
        return Result<double>::Error("face " + std::to_string(f) + " has vertex index " +
                                     std::to_string(v) + " outside [0, " +
                                     std::to_string(vertex_count) + ")");
      }
    }
    Loop sorted = face;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
      return Result<double>::Error("face " + std::to_string(f) + " repeats a vertex index");
    }
    const double twice_area = NewellNormal(vertices, face).norm();
    if (!(twice_area > kAreaTolerance * scale * scale)) {
      std::ostringstream out;
      out << "face " << f << " is degenerate (area " << 0.5 * twice_area << " m^2)";
      return Result<double>::Error(out.str());
    }
  }
  return scale;
}

// Union-find over shared edges: two neighbouring faces join one group when
// their normals agree in sign and each lies within the coplanar tolerance
// of the other's plane. Returns each face's parent (FindRoot gives its group).
std::vector<int> GroupCoplanarFaces(const std::vector<Vec3>& vertices,
                                    const std::vector<Loop>& faces,
                                    const std::unordered_map<std::int64_t, int>& edge_face,
                                    double scale) {
  const int vertex_count = static_cast<int>(vertices.size());
  const int face_count = static_cast<int>(faces.size());
  std::vector<Plane> planes(face_count);
  for (int f = 0; f < face_count; ++f) planes[f] = PlaneOfLoop(vertices, faces[f]);
  std::vector<int> parent(face_count);
  std::iota(parent.begin(), parent.end(), 0);
  const double coplanar_distance = kCoplanarTolerance * scale;
  for (int f = 0; f < face_count; ++f) {
    const Loop& face = faces[f];
    for (std::size_t i = 0; i < face.size(); ++i) {
      const int from = face[i];
      const int to = face[(i + 1) % face.size()];
      const int g = edge_face.at(EdgeKey(to, from, vertex_count));
      if (g <= f) continue;
      if (planes[f].normal.dot(planes[g].normal) > 0.0 &&
          MaxDistanceToPlane(vertices, faces[g], planes[f]) <= coplanar_distance &&
          MaxDistanceToPlane(vertices, faces[f], planes[g]) <= coplanar_distance) {
        parent[FindRoot(parent, f)] = FindRoot(parent, g);
      }
    }
  }
  return parent;
}

// The boundary of one group of faces (edges whose twin lies in another
// group), chained into one counter-clockwise loop; an error when it is not
// a single simple polygon.
Result<Loop> GroupBoundary(const std::vector<Loop>& faces, const std::vector<int>& group_faces,
                           const std::unordered_map<std::int64_t, int>& edge_face, int vertex_count,
                           std::vector<int>* parent) {
  const int group = FindRoot(*parent, group_faces[0]);
  const std::string around = "coplanar faces around face " + std::to_string(group_faces[0]);
  // Successor of each boundary vertex along the group's boundary.
  std::unordered_map<int, int> successor;
  int boundary_edge_count = 0;
  int start = -1;
  for (int f : group_faces) {
    const Loop& face = faces[f];
    for (std::size_t i = 0; i < face.size(); ++i) {
      const int from = face[i];
      const int to = face[(i + 1) % face.size()];
      const int g = edge_face.at(EdgeKey(to, from, vertex_count));
      if (FindRoot(*parent, g) == group) continue;
      if (!successor.emplace(from, to).second) {
        return Result<Loop>::Error("coplanar faces around face " + std::to_string(f) +
                                   " merge into a polygon that touches itself at vertex " +
                                   std::to_string(from));
      }
      ++boundary_edge_count;
      start = from;
    }
  }
  if (start < 0) return Result<Loop>::Error(around + " enclose nothing");
  Loop loop;
  int v = start;
  do {
    loop.push_back(v);
    const auto it = successor.find(v);
    if (it == successor.end() || static_cast<int>(loop.size()) > boundary_edge_count) {
      return Result<Loop>::Error(around + " do not merge into a single polygon");
    }
    v = it->second;
  } while (v != start);
  if (static_cast<int>(loop.size()) != boundary_edge_count) {
    return Result<Loop>::Error(around + " merge into a polygon with a hole");
  }
  return loop;
}

// Merges coplanar neighbouring faces: faces are grouped by union-find over
// shared edges, and each group's boundary (edges whose twin lies in another
// group) is chained into one counter-clockwise loop. Interior edges and
// vertices of a group disappear with it.
Result<std::vector<Loop>> MergeCoplanarFaces(const std::vector<Vec3>& vertices,
                                             const std::vector<Loop>& faces,
                                             const std::unordered_map<std::int64_t, int>& edge_face,
                                             double scale) {
  const int face_count = static_cast<int>(faces.size());
  std::vector<int> parent = GroupCoplanarFaces(vertices, faces, edge_face, scale);
  std::vector<std::vector<int>> group_faces(face_count);
  for (int f = 0; f < face_count; ++f) group_faces[FindRoot(parent, f)].push_back(f);
  std::vector<Loop> merged;
  for (int group = 0; group < face_count; ++group) {
    if (group_faces[group].empty()) continue;
    if (group_faces[group].size() == 1) {
      merged.push_back(faces[group_faces[group][0]]);
      continue;
    }
    Result<Loop> loop = GroupBoundary(faces, group_faces[group], edge_face,
                                      static_cast<int>(vertices.size()), &parent);
    if (!loop.ok()) return loop.status();
    merged.push_back(std::move(loop).value());
  }
  return merged;
}

// After merging, a vertex on only two faces lies on the edge between them
// (two planes meet in a line), so it is a collinear point on both polygon
// boundaries and is removed from both. If it is not collinear the input was
// not a convex polyhedron.
Status RemoveCollinearVertices(const std::vector<Vec3>& vertices, double scale,
                               std::vector<Loop>& loops) {
  std::vector<int> face_count(vertices.size(), 0);
  for (const Loop& loop : loops) {
    for (int v : loop) ++face_count[v];
  }
  for (Loop& loop : loops) {
    Loop kept;
    kept.reserve(loop.size());
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const int v = loop[i];
      if (face_count[v] != 2) {
        kept.push_back(v);
        continue;
      }
      const Vec3& previous = vertices[loop[(i + loop.size() - 1) % loop.size()]];
      const Vec3& next = vertices[loop[(i + 1) % loop.size()]];
      const Vec3 along = next - previous;
      const double off_line = along.squaredNorm() > 0.0
                                  ? (vertices[v] - previous).cross(along).norm() / along.norm()
                                  : (vertices[v] - previous).norm();
      if (off_line > kPlaneTolerance * scale) {
        return Status::Error("vertex " + std::to_string(v) + " " + Describe(vertices[v]) +
                             " lies on only two faces but is not on the edge between them");
      }
    }
    if (kept.size() < 3) {
      return Status::Error("a face collapses to fewer than 3 vertices after removing " +
                           std::string("collinear vertices"));
    }
    loop = std::move(kept);
  }
  return Status::Ok();
}

// Pairs every directed edge u->v with its twin v->u: the faces must make a
// closed, consistently oriented 2-manifold. Returns each directed edge's
// face.
Result<EdgeFaces> PairDirectedEdges(int vertex_count, const std::vector<Loop>& faces) {
  EdgeFaces edge_face;
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
    const Loop& face = faces[f];
    for (std::size_t i = 0; i < face.size(); ++i) {
      const int from = face[i];
      const int to = face[(i + 1) % face.size()];
      if (!edge_face.emplace(EdgeKey(from, to, vertex_count), f).second) {
        return Result<EdgeFaces>::Error(
            "directed edge " + std::to_string(from) + "->" + std::to_string(to) +
            " is used by two faces (non-manifold or inconsistently oriented)");
      }
    }
  }
  for (const auto& [key, face] : edge_face) {
    const int from = static_cast<int>(key / vertex_count);
    const int to = static_cast<int>(key % vertex_count);
    if (edge_face.count(EdgeKey(to, from, vertex_count)) == 0) {
      return Result<EdgeFaces>::Error("the surface is open: edge " + std::to_string(from) + "->" +
                                      std::to_string(to) + " of face " + std::to_string(face) +
                                      " has no opposite edge");
    }
  }
  return edge_face;
}

// Copies the vertices the loops use, in their input order, and renumbers
// the loops to match.
void KeepUsedVertices(const std::vector<Vec3>& vertices, std::vector<Loop>* loops,
                      ConvexPolyhedron* polyhedron) {
  const int vertex_count = static_cast<int>(vertices.size());
  std::vector<int> new_index(vertex_count, -1);
  for (const Loop& loop : *loops) {
    for (int v : loop) new_index[v] = 0;
  }
  for (int v = 0; v < vertex_count; ++v) {
    if (new_index[v] < 0) continue;
    new_index[v] = static_cast<int>(polyhedron->vertices.size());
    polyhedron->vertices.push_back(vertices[v]);
  }
  for (Loop& loop : *loops) {
    for (int& v : loop) v = new_index[v];
  }
}

// Half-edges: the first time an undirected edge {u, v} is met as u->v it
// gets the pair (2k: u->v, 2k+1: v->u), so twins sit at h ^ 1.
Status BuildHalfEdges(const std::vector<Loop>& loops, ConvexPolyhedron* polyhedron) {
  const int used_count = static_cast<int>(polyhedron->vertices.size());
  std::unordered_map<std::int64_t, int> half_edge_of;
  std::vector<int> loop_half_edges;
  for (int f = 0; f < static_cast<int>(loops.size()); ++f) {
    const Loop& loop = loops[f];
    loop_half_edges.clear();
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const int from = loop[i];
      const int to = loop[(i + 1) % loop.size()];
      int h;
      const auto it = half_edge_of.find(EdgeKey(from, to, used_count));
      if (it != half_edge_of.end()) {
        h = it->second;
      } else {
        h = static_cast<int>(polyhedron->half_edges.size());
        polyhedron->half_edges.push_back({from, -1, -1});
        polyhedron->half_edges.push_back({to, -1, -1});
        half_edge_of.emplace(EdgeKey(from, to, used_count), h);
        half_edge_of.emplace(EdgeKey(to, from, used_count), h + 1);
      }
      if (polyhedron->half_edges[h].face >= 0) {
        return Status::Error("after merging, edge " + std::to_string(from) + "->" +
                             std::to_string(to) + " borders two faces on the same side");
      }
      polyhedron->half_edges[h].face = f;
      loop_half_edges.push_back(h);
    }
    for (std::size_t i = 0; i < loop_half_edges.size(); ++i) {
      polyhedron->half_edges[loop_half_edges[i]].next =
          loop_half_edges[(i + 1) % loop_half_edges.size()];
    }
    polyhedron->faces.push_back({loop_half_edges[0], Vec3::Zero(), 0.0});
  }
  for (const ConvexPolyhedron::HalfEdge& half_edge : polyhedron->half_edges) {
    if (half_edge.face < 0) return Status::Error("after merging, an edge borders only one face");
  }
  return Status::Ok();
}

// Each vertex's outgoing half-edges must form a single fan, or the surface
// is pinched at that vertex; and V - E + F = 2 (Euler) for one closed
// surface of genus 0.
Status CheckTopology(ConvexPolyhedron* polyhedron) {
  const int used_count = static_cast<int>(polyhedron->vertices.size());
  polyhedron->vertex_half_edge.assign(used_count, -1);
  std::vector<int> degree(used_count, 0);
  for (int h = 0; h < static_cast<int>(polyhedron->half_edges.size()); ++h) {
    polyhedron->vertex_half_edge[polyhedron->half_edges[h].origin] = h;
    ++degree[polyhedron->half_edges[h].origin];
  }
  for (int v = 0; v < used_count; ++v) {
    const int first = polyhedron->vertex_half_edge[v];
    int h = first;
    int fan_size = 0;
    do {
      ++fan_size;
      h = polyhedron->half_edges[ConvexPolyhedron::Twin(h)].next;
    } while (h != first && fan_size <= degree[v]);
    if (fan_size != degree[v]) {
      return Status::Error("the surface is pinched (non-manifold) at vertex " +
                           Describe(polyhedron->vertices[v]));
    }
  }
  const int euler =
      used_count - polyhedron->EdgeCount() + static_cast<int>(polyhedron->faces.size());
  if (euler != 2) {
    return Status::Error("V - E + F = " + std::to_string(euler) +
                         ", expected 2 for a single closed convex surface");
  }
  return Status::Ok();
}

// Every face planar (Newell plane) and convex, and every vertex behind
// every face plane: the solid is convex.
Status SetFacePlanes(const std::vector<Loop>& loops, double scale, ConvexPolyhedron* polyhedron) {
  const double plane_distance = kPlaneTolerance * scale;
  for (int f = 0; f < static_cast<int>(loops.size()); ++f) {
    const Loop& loop = loops[f];
    const Plane plane = PlaneOfLoop(polyhedron->vertices, loop);
    const double off_plane = MaxDistanceToPlane(polyhedron->vertices, loop, plane);
    if (off_plane > plane_distance) {
      std::ostringstream out;
      out << "face " << f << " is not planar: a vertex is " << off_plane << " m off its plane";
      return Status::Error(out.str());
    }
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const Vec3& a = polyhedron->vertices[loop[i]];
      const Vec3& b = polyhedron->vertices[loop[(i + 1) % loop.size()]];
      const Vec3& c = polyhedron->vertices[loop[(i + 2) % loop.size()]];
      const Vec3 ab = b - a;
      const Vec3 bc = c - b;
      if (ab.cross(bc).dot(plane.normal) < -kPlaneTolerance * ab.norm() * bc.norm()) {
        return Status::Error("face " + std::to_string(f) + " is not convex at vertex " +
                             Describe(b));
      }
    }
    polyhedron->faces[f].normal = plane.normal;
    polyhedron->faces[f].offset = plane.offset;
  }
  for (int f = 0; f < static_cast<int>(polyhedron->faces.size()); ++f) {
    const ConvexPolyhedron::Face& face = polyhedron->faces[f];
    for (const Vec3& vertex : polyhedron->vertices) {
      const double in_front = face.normal.dot(vertex) - face.offset;
      if (in_front > plane_distance) {
        std::ostringstream out;
        out << "not convex: vertex " << Describe(vertex) << " is " << in_front
            << " m in front of face " << f;
        return Status::Error(out.str());
      }
    }
  }
  return Status::Ok();
}

// Each edge direction once, for the separating-axis test.
void FindEdgeDirections(ConvexPolyhedron* polyhedron) {
  for (int e = 0; e < polyhedron->EdgeCount(); ++e) {
    const Vec3 direction = (polyhedron->vertices[polyhedron->half_edges[2 * e + 1].origin] -
                            polyhedron->vertices[polyhedron->half_edges[2 * e].origin])
                               .normalized();
    const bool known =
        std::any_of(polyhedron->edge_directions.begin(), polyhedron->edge_directions.end(),
                    [&](const Vec3& other) {
                      return direction.cross(other).norm() <= kEdgeDirectionTolerance;
                    });
    if (!known) polyhedron->edge_directions.push_back(direction);
  }
}

}  // namespace

// Steps: check the polygons; pair every directed edge u->v with its twin
// v->u (closed, consistently oriented 2-manifold); merge coplanar
// neighbours; drop collinear and unused vertices; build half-edges with
// twins at h ^ 1; verify the vertex fans, Euler's V - E + F = 2, planarity,
// convexity of every face and of the whole solid; then planes (Newell),
// unique edge directions and the volume centroid.
Result<ConvexPolyhedron> MakeConvexPolyhedron(const std::vector<Vec3>& vertices,
                                              const std::vector<std::vector<int>>& faces) {
  const Result<double> checked = CheckInput(vertices, faces);
  if (!checked.ok()) return Fail(checked.message());
  const double scale = checked.value();
  const Result<EdgeFaces> edge_face = PairDirectedEdges(static_cast<int>(vertices.size()), faces);
  if (!edge_face.ok()) return Fail(edge_face.message());
  Result<std::vector<Loop>> merged = MergeCoplanarFaces(vertices, faces, *edge_face, scale);
  if (!merged.ok()) return Fail(merged.message());
  std::vector<Loop> loops = std::move(merged).value();
  if (Status status = RemoveCollinearVertices(vertices, scale, loops); !status.ok()) {
    return Fail(status.message());
  }
  ConvexPolyhedron polyhedron;
  KeepUsedVertices(vertices, &loops, &polyhedron);
  for (const Status& status : {BuildHalfEdges(loops, &polyhedron), CheckTopology(&polyhedron),
                               SetFacePlanes(loops, scale, &polyhedron)}) {
    if (!status.ok()) return Fail(status.message());
  }
  FindEdgeDirections(&polyhedron);
  const Result<MassProperties> volume = TriangleMeshMassProperties(1.0, polyhedron.Triangulate());
  if (!volume.ok()) return Fail(volume.message());
  polyhedron.centroid = volume.value().center_of_mass;
  for (int k = 0; k < 6; ++k) {
    Vec3 axis = Vec3::Zero();
    axis[k / 2] = k % 2 == 0 ? 1.0 : -1.0;
    polyhedron.axis_support[k] = polyhedron.SupportVertex(axis);
  }
  return polyhedron;
}

}  // namespace rigid_body_sim::physics
