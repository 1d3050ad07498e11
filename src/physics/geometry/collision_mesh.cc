// Static triangle meshes: welding, edge adjacency and the bounding-volume
// hierarchy (CollisionMesh::Make).
#include "rigid_body_sim/physics/collision_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>

#include "physics/geometry/mesh_orientation.h"

namespace rigid_body_sim::physics {
namespace {

// Leaves hold at most this many triangles.
constexpr int kLeafTriangles = 4;
// A triangle whose doubled area is below this fraction of its longest edge
// squared is degenerate (a sliver or a repeated vertex) and is dropped.
constexpr double kDegenerateAreaFraction = 1e-12;
// sin of the fold angle below which two neighbouring triangles are coplanar.
constexpr double kFlatFoldSine = 1e-7;

struct VertexKey {
  std::uint64_t bits[3];
  friend bool operator==(const VertexKey& x, const VertexKey& y) {
    return std::memcmp(x.bits, y.bits, sizeof(x.bits)) == 0;
  }
};

struct VertexKeyHash {
  std::size_t operator()(const VertexKey& key) const {
    std::uint64_t hash = 0x9e3779b97f4a7c15ull;
    for (const std::uint64_t bits : key.bits) hash = (hash ^ bits) * 0x100000001b3ull;
    return static_cast<std::size_t>(hash ^ (hash >> 29));
  }
};

VertexKey KeyOf(const Vec3& vertex) {
  VertexKey key{};
  for (int i = 0; i < 3; ++i) {
    const double value = vertex[i] == 0.0 ? 0.0 : vertex[i];  // -0 and +0 weld
    std::memcpy(&key.bits[i], &value, sizeof(value));
  }
  return key;
}

std::string Describe(const char* what, std::size_t index, const std::string& problem) {
  std::ostringstream out;
  out << "triangle mesh " << what << " " << index << ": " << problem;
  return out.str();
}

}  // namespace

// Builds the mesh: vertices at bit-equal positions are welded (mesh files
// repeat a vertex per triangle), triangles of zero area are dropped, each
// triangle's normal is (v1 - v0) x (v2 - v0) normalised, then the winding
// (Orient), the edge adjacency (FindNeighbours) and the tree (BuildTree).
Result<std::shared_ptr<const CollisionMesh>> CollisionMesh::Make(const TriangleMesh& mesh) {
  using Out = Result<std::shared_ptr<const CollisionMesh>>;
  if (mesh.triangles.size() > kMaxTriangles) {
    return Out::Error("triangle mesh has " + std::to_string(mesh.triangles.size()) +
                      " triangles, allowed at most " + std::to_string(kMaxTriangles));
  }
  std::shared_ptr<CollisionMesh> built(new CollisionMesh());
  std::unordered_map<VertexKey, int, VertexKeyHash> welded;
  std::vector<int> weld_of(mesh.vertices.size());
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Vec3& vertex = mesh.vertices[v];
    if (!vertex.allFinite()) {
      return Out::Error(Describe("vertex", v, "coordinates must be finite"));
    }
    const auto [it, inserted] =
        welded.try_emplace(KeyOf(vertex), static_cast<int>(built->vertices_.size()));
    if (inserted) built->vertices_.push_back(vertex);
    weld_of[v] = it->second;
  }
  const int vertex_count = static_cast<int>(mesh.vertices.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    Triangle triangle;
    for (int k = 0; k < 3; ++k) {
      const int index = mesh.triangles[t][k];
      if (index < 0 || index >= vertex_count) {
        return Out::Error(Describe("triangle", t,
                                   "vertex index " + std::to_string(index) + " outside [0, " +
                                       std::to_string(vertex_count - 1) + "]"));
      }
      triangle.vertices[k] = weld_of[index];
    }
    const Vec3& a = built->vertices_[triangle.vertices[0]];
    const Vec3& b = built->vertices_[triangle.vertices[1]];
    const Vec3& c = built->vertices_[triangle.vertices[2]];
    const Vec3 cross = (b - a).cross(c - a);
    const double longest =
        std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if (!(cross.norm() > kDegenerateAreaFraction * longest)) continue;
    triangle.normal = cross.normalized();
    built->triangles_.push_back(triangle);
  }
  if (built->triangles_.empty()) {
    return Out::Error("triangle mesh has no triangle of non-zero area (of " +
                      std::to_string(mesh.triangles.size()) + ")");
  }
  built->Orient();
  built->FindNeighbours();
  built->BuildTree();
  return Out(std::shared_ptr<const CollisionMesh>(std::move(built)));
}

// Reverses the triangles that OrientComponents finds wound against their
// component (two vertices swapped, the normal negated) and makes those of
// open components two-sided.
void CollisionMesh::Orient() {
  std::vector<std::array<int, 3>> corners(triangles_.size());
  for (std::size_t t = 0; t < triangles_.size(); ++t) corners[t] = triangles_[t].vertices;
  const MeshOrientation orientation = OrientComponents(vertices_, corners);
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    Triangle& triangle = triangles_[t];
    if (orientation.flip[t] != 0) {
      std::swap(triangle.vertices[1], triangle.vertices[2]);
      triangle.normal = -triangle.normal;
    }
    triangle.two_sided = orientation.open[t] != 0;
  }
}

// Edge adjacency by sorting the edges on their vertex pair. An edge of
// exactly two triangles gets the other's normal, negated when the two run
// the edge the same way (after Orient, only in a non-orientable component),
// and its fold: with w the neighbour's third vertex and v a vertex of the
// edge, n . (w - v) < 0 means the surface turns away from the normal side
// (convex), > 0 towards it (concave), and about 0 means coplanar.
void CollisionMesh::FindNeighbours() {
  std::vector<std::pair<std::uint64_t, int>> edges;  // (vertex pair, 3 t + k)
  edges.reserve(3 * triangles_.size());
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const auto v0 = static_cast<std::uint32_t>(triangles_[t].vertices[k]);
      const auto v1 = static_cast<std::uint32_t>(triangles_[t].vertices[(k + 1) % 3]);
      const std::uint64_t key =
          (std::uint64_t{std::min(v0, v1)} << 32) | std::uint64_t{std::max(v0, v1)};
      edges.emplace_back(key, static_cast<int>(3 * t + k));
      triangles_[t].neighbour_normals[k] = triangles_[t].normal;
      triangles_[t].edge_folds[k] = EdgeFold::kBoundary;
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t begin = 0; begin < edges.size();) {
    std::size_t end = begin + 1;
    while (end < edges.size() && edges[end].first == edges[begin].first) ++end;
    if (end - begin == 2) {
      for (int side = 0; side < 2; ++side) {
        const int own = edges[begin + side].second;
        const int other = edges[begin + 1 - side].second;
        Triangle& triangle = triangles_[own / 3];
        const Triangle& neighbour = triangles_[other / 3];
        const int k = own % 3;
        const int j = other % 3;
        const bool same_direction =
            triangle.vertices[k] == neighbour.vertices[j];  // both run v0 -> v1
        const Vec3& start = vertices_[triangle.vertices[k]];
        const Vec3& third = vertices_[neighbour.vertices[(j + 2) % 3]];
        const double fold = triangle.normal.dot(third - start) / (third - start).norm();
        triangle.neighbour_normals[k] = same_direction ? -neighbour.normal : neighbour.normal;
        triangle.edge_folds[k] = fold < -kFlatFoldSine  ? EdgeFold::kConvex
                                 : fold > kFlatFoldSine ? EdgeFold::kConcave
                                                        : EdgeFold::kFlat;
      }
    }
    begin = end;
  }
}

// Top-down construction of an axis-aligned box tree (Ericson 2005, Real-Time
// Collision Detection, section 6.2.1): a node's triangles are split at the
// median of their centroids along the longest axis of the centroids' box
// (a balanced tree, depth log2(n / 4)), until at most four remain. Nodes are
// stored depth first, so a left child follows its parent; an explicit stack
// replaces recursion.
void CollisionMesh::BuildTree() {
  const int count = static_cast<int>(triangles_.size());
  std::vector<int> order(count);
  std::vector<Vec3> centroids(count);
  for (int t = 0; t < count; ++t) {
    order[t] = t;
    const auto& v = triangles_[t].vertices;
    centroids[t] = (vertices_[v[0]] + vertices_[v[1]] + vertices_[v[2]]) / 3.0;
  }
  struct Task {
    int begin, end, parent;  // parent: the node whose right child this is, or -1
  };
  std::vector<Task> stack{{0, count, -1}};
  nodes_.reserve(2 * count / kLeafTriangles + 1);
  while (!stack.empty()) {
    const Task task = stack.back();
    stack.pop_back();
    const int index = static_cast<int>(nodes_.size());
    if (task.parent >= 0) nodes_[task.parent].first = index;
    Node node;
    node.lower = Vec3::Constant(std::numeric_limits<double>::infinity());
    node.upper = -node.lower;
    Vec3 centroid_lower = node.lower;
    Vec3 centroid_upper = node.upper;
    for (int i = task.begin; i < task.end; ++i) {
      for (const int v : triangles_[order[i]].vertices) {
        node.lower = node.lower.cwiseMin(vertices_[v]);
        node.upper = node.upper.cwiseMax(vertices_[v]);
      }
      centroid_lower = centroid_lower.cwiseMin(centroids[order[i]]);
      centroid_upper = centroid_upper.cwiseMax(centroids[order[i]]);
    }
    if (task.end - task.begin <= kLeafTriangles) {
      node.first = task.begin;
      node.count = task.end - task.begin;
      nodes_.push_back(node);
      continue;
    }
    nodes_.push_back(node);
    int axis = 0;
    (centroid_upper - centroid_lower).maxCoeff(&axis);
    const int middle = task.begin + (task.end - task.begin) / 2;
    std::nth_element(order.begin() + task.begin, order.begin() + middle, order.begin() + task.end,
                     [&](int x, int y) { return centroids[x][axis] < centroids[y][axis]; });
    stack.push_back({middle, task.end, index});
    stack.push_back({task.begin, middle, -1});
  }
  std::vector<Triangle> sorted(count);
  for (int i = 0; i < count; ++i) sorted[i] = triangles_[order[i]];
  triangles_.swap(sorted);
}

double CollisionMesh::BoundingRadius(const Vec3& center) const {
  double radius_squared = 0.0;
  for (const Vec3& vertex : vertices_) {
    radius_squared = std::max(radius_squared, (vertex - center).squaredNorm());
  }
  return std::sqrt(radius_squared);
}

namespace {

bool TriangleOverlapsBox(const std::vector<Vec3>& vertices, const CollisionMesh::Triangle& triangle,
                         const Vec3& lower, const Vec3& upper) {
  const Vec3& a = vertices[triangle.vertices[0]];
  const Vec3& b = vertices[triangle.vertices[1]];
  const Vec3& c = vertices[triangle.vertices[2]];
  const Vec3 triangle_lower = a.cwiseMin(b).cwiseMin(c);
  const Vec3 triangle_upper = a.cwiseMax(b).cwiseMax(c);
  return (triangle_lower.array() <= upper.array()).all() &&
         (lower.array() <= triangle_upper.array()).all();
}

}  // namespace

void CollisionMesh::QueryBox(const Vec3& lower, const Vec3& upper, std::vector<int>* out) const {
  thread_local std::vector<int> stack;
  stack.clear();
  stack.push_back(0);
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    const int index = stack.back();
    stack.pop_back();
    if (!((node.lower.array() <= upper.array()).all() &&
          (lower.array() <= node.upper.array()).all())) {
      continue;
    }
    if (node.count > 0) {
      for (int t = node.first; t < node.first + node.count; ++t) {
        if (TriangleOverlapsBox(vertices_, triangles_[t], lower, upper)) out->push_back(t);
      }
      continue;
    }
    stack.push_back(node.first);
    stack.push_back(index + 1);
  }
}

void CollisionMesh::BruteForceQueryBox(const Vec3& lower, const Vec3& upper,
                                       std::vector<int>* out) const {
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    if (TriangleOverlapsBox(vertices_, triangles_[t], lower, upper)) {
      out->push_back(static_cast<int>(t));
    }
  }
}

}  // namespace rigid_body_sim::physics
