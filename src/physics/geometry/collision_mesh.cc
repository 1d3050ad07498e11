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
#include "physics/geometry/wide_box_tree.h"

namespace rigid_body_sim::physics {
namespace {

// Leaves hold at most this many triangles: rays test fewer triangles with
// two than with four (100,000 rays on a 99k-triangle terrain, one thread:
// 88 ms with two, 100 ms with four).
constexpr int kLeafTriangles = 2;
// Runs of at most this many triangles stay in the order they have; the
// order, which contacts follow, is that of a binary tree with leaves of
// four, as before the tree was four-wide.
constexpr int kSortedTriangles = 4;
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

// The four-wide tree over the triangles' boxes (WideBoxTree, split at the
// median centroid), and the triangles stored in its order, so a leaf's
// triangles are consecutive. The order is the one a binary tree of the
// same splits gives, so contacts (which follow triangle indices) are as
// they were before the tree was four-wide.
void CollisionMesh::BuildTree() {
  std::vector<Aabb> boxes(triangles_.size());
  std::vector<Vec3> centroids(triangles_.size());
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    const auto& v = triangles_[t].vertices;
    boxes[t].min = vertices_[v[0]].cwiseMin(vertices_[v[1]]).cwiseMin(vertices_[v[2]]);
    boxes[t].max = vertices_[v[0]].cwiseMax(vertices_[v[1]]).cwiseMax(vertices_[v[2]]);
    centroids[t] = (vertices_[v[0]] + vertices_[v[1]] + vertices_[v[2]]) / 3.0;
  }
  std::vector<int> order;
  tree_ = std::make_shared<WideBoxTree>(WideBoxTree::Build(
      boxes, WideBoxTree::BuildSettings{kLeafTriangles, kSortedTriangles, &centroids}, &order));
  std::vector<Triangle> sorted(triangles_.size());
  for (std::size_t i = 0; i < sorted.size(); ++i) sorted[i] = triangles_[order[i]];
  triangles_.swap(sorted);
  ray_triangles_.resize(triangles_.size());
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    const auto& v = triangles_[t].vertices;
    ray_triangles_[t] = {vertices_[v[0]], vertices_[v[1]] - vertices_[v[0]],
                         vertices_[v[2]] - vertices_[v[0]], triangles_[t].normal,
                         triangles_[t].two_sided};
  }
  double radius_squared = 0.0;
  for (const Vec3& vertex : vertices_)
    radius_squared = std::max(radius_squared, vertex.squaredNorm());
  radius_about_origin_ = std::sqrt(radius_squared);
}

const Vec3& CollisionMesh::lower() const { return tree_->bounds().min; }
const Vec3& CollisionMesh::upper() const { return tree_->bounds().max; }

double CollisionMesh::BoundingRadius(const Vec3& center) const {
  if (center.isZero(0.0)) return radius_about_origin_;
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
  tree_->QueryBox(Aabb{lower, upper}, [&](int first, int count) {
    for (int t = first; t < first + count; ++t) {
      if (TriangleOverlapsBox(vertices_, triangles_[t], lower, upper)) out->push_back(t);
    }
  });
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
