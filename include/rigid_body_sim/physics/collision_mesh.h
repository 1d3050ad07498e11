// Static triangle meshes for concave environments (bins, shelves, tables,
// terrain): the triangles with their edge adjacency, in a bounding-volume
// hierarchy built once. The winding given need not be consistent: each
// connected component is wound consistently when the mesh is built, a
// closed one with its normals outward. A closed component's triangles
// collide on their front (outer) side only: the underside of a bin's 5 mm
// floor must not hold up a box resting on the floor's top. An open
// component's (a sheet, a terrain, a wall of one layer) collide on
// whichever side a body's centre is.
#ifndef RIGID_BODY_SIM_PHYSICS_COLLISION_MESH_H_
#define RIGID_BODY_SIM_PHYSICS_COLLISION_MESH_H_

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

class WideBoxTree;

class CollisionMesh {
 public:
  // Most triangles a mesh may have (16 Mi): its tree, adjacency and ray
  // records (about 300 bytes a triangle) then take 5 GB at most.
  static constexpr std::size_t kMaxTriangles = std::size_t{1} << 24;

  enum class EdgeFold : std::uint8_t { kFlat, kConvex, kConcave, kBoundary };

  struct Triangle {
    std::array<int, 3> vertices{};  // counter-clockwise seen from the side `normal` points to
    Vec3 normal = Vec3::UnitZ();    // unit
    // Of an open component: collides from both sides.
    bool two_sided = false;
    // Edge k runs from vertices[k] to vertices[(k + 1) % 3]. The normal of
    // the triangle across it, oriented as this one (this triangle's own
    // normal for a boundary or non-manifold edge), and the edge's fold seen
    // from the side `normal` points to.
    std::array<Vec3, 3> neighbour_normals{Vec3::UnitZ(), Vec3::UnitZ(), Vec3::UnitZ()};
    std::array<EdgeFold, 3> edge_folds{};
  };

  // Welds vertices at equal positions, drops triangles of zero area, winds
  // each connected component consistently, finds each edge's neighbour and
  // builds the tree. Fails with a message for a
  // vertex that is not finite, an index out of range, no triangle of
  // non-zero area, or more than kMaxTriangles triangles.
  static Result<std::shared_ptr<const CollisionMesh>> Make(const TriangleMesh& mesh);

  const std::vector<Vec3>& vertices() const { return vertices_; }
  // In tree order (leaves hold consecutive triangles), not the input order.
  const std::vector<Triangle>& triangles() const { return triangles_; }

  // What a ray test reads of a triangle: its first vertex and its edges to
  // the second and the third, as triangles() winds them.
  struct RayTriangle {
    Vec3 corner;             // m, vertices[0]
    Vec3 edge1;              // m, vertices[1] - vertices[0]
    Vec3 edge2;              // m, vertices[2] - vertices[0]
    Vec3 normal;             // Triangle::normal
    bool two_sided = false;  // Triangle::two_sided
  };
  // In triangles()' order, so that a leaf's triangles are one stretch of
  // 104-byte records: a ray read a 128-byte Triangle and then its three
  // vertices, one dependent load after another (100,000 rays on a 99k-
  // triangle terrain and 1,000 boxes, one thread: 66 -> 60 ms).
  const std::vector<RayTriangle>& ray_triangles() const { return ray_triangles_; }
  // The tree of the triangles' boxes (physics/geometry/wide_box_tree.h):
  // leaf items are triangle indices.
  const WideBoxTree& tree() const { return *tree_; }

  // The box of every vertex (m, mesh frame): the tree's bounds.
  const Vec3& lower() const;
  const Vec3& upper() const;
  // The largest distance of a vertex from `center` (m). About the origin it
  // is kept from the build, since the time-of-impact search asks for it on
  // every pair with the mesh and a terrain has many vertices.
  double BoundingRadius(const Vec3& center) const;

  // Appends to `out` the triangles whose boxes overlap the closed box
  // [lower, upper] (mesh frame), walking the tree.
  void QueryBox(const Vec3& lower, const Vec3& upper, std::vector<int>* out) const;
  // The same set by testing every triangle: the reference for QueryBox.
  void BruteForceQueryBox(const Vec3& lower, const Vec3& upper, std::vector<int>* out) const;

 private:
  CollisionMesh() = default;
  void Orient();
  void FindNeighbours();
  void BuildTree();

  std::vector<Vec3> vertices_;
  std::vector<Triangle> triangles_;
  std::vector<RayTriangle> ray_triangles_;
  std::shared_ptr<const WideBoxTree> tree_;
  double radius_about_origin_ = 0.0;  // m
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_COLLISION_MESH_H_
