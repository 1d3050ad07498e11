#include "io/urdf_meshes.h"

#include <utility>

#include "io/urdf_checks.h"
#include "io/urdf_elements.h"
#include "rigid_body_sim/io/mesh_process.h"

namespace rigid_body_sim::io {

using physics::ConvexPolyhedron;
using physics::FormatNumber;
using physics::MassProperties;
using physics::Result;
using physics::Status;
using physics::Vec3;

namespace {

// A hull's extents within the shape limits (kMinShapeSize..kMaxShapeSize,
// and the aspect ratio).
Status CheckHullExtents(const ConvexPolyhedron& hull, const std::string& what,
                        double max_aspect_ratio) {
  Vec3 lower = hull.vertices.front();
  Vec3 upper = lower;
  for (const Vec3& vertex : hull.vertices) {
    lower = lower.cwiseMin(vertex);
    upper = upper.cwiseMax(vertex);
  }
  return CheckShapeExtents(upper - lower, what, max_aspect_ratio);
}

}  // namespace

Result<ShapeWithMass> UrdfMeshes::Triangles(const std::string& uri, const Vec3& scale,
                                            const std::string& where) {
  using Out = Result<ShapeWithMass>;
  Result<std::shared_ptr<const physics::CollisionMesh>> mesh = LoadTriangles(uri, scale);
  if (!mesh.ok()) return Out::Error(where + ": " + mesh.message());
  const Vec3 extent = (*mesh)->upper() - (*mesh)->lower();
  if (!(extent.maxCoeff() <= kMaxShapeSize)) {
    return Out::Error(where + " <mesh> triangles span " + FormatNumber(extent.maxCoeff()) +
                      " m, above the allowed " + FormatNumber(kMaxShapeSize) + " m");
  }
  physics::TriangleMesh solid;
  solid.vertices = (*mesh)->vertices();
  for (const physics::CollisionMesh::Triangle& triangle : (*mesh)->triangles()) {
    solid.triangles.emplace_back(triangle.vertices[0], triangle.vertices[1], triangle.vertices[2]);
  }
  Result<MassProperties> mass =
      physics::TriangleMeshMassProperties(options_.default_density, solid);
  return ShapeWithMass{{physics::StaticMesh{*mesh}}, mass.ok() ? *mass : MassProperties{}};
}

Result<ShapeWithMass> UrdfMeshes::Hull(const std::string& uri, const Vec3& scale,
                                       const std::string& where) {
  Result<std::shared_ptr<const ConvexPolyhedron>> hull = LoadHull(uri, scale);
  if (!hull.ok()) return Result<ShapeWithMass>::Error(where + ": " + hull.message());
  if (Status status = CheckHullExtents(**hull, where + " <mesh> hull", max_aspect_ratio_);
      !status.ok()) {
    return status;
  }
  return ShapeWithMass{{*hull},
                       physics::PolyhedronMassProperties(options_.default_density, **hull)};
}

Result<ShapeWithMass> UrdfMeshes::Pieces(const std::string& uri, const Vec3& scale, PiecesRule rule,
                                         const std::string& where) {
  auto pieces = LoadPieces(uri, scale, rule);
  if (!pieces.ok()) return Result<ShapeWithMass>::Error(where + ": " + pieces.message());
  ShapeWithMass shape;
  std::vector<MassProperties> masses;
  for (const ConvexPolyhedron& piece : **pieces) {
    if (Status status = CheckHullExtents(piece, where + " <mesh> piece", max_aspect_ratio_);
        !status.ok()) {
      return status;
    }
    // Aliases the list, which keeps every piece alive as long as one is used.
    shape.geometry.push_back(std::shared_ptr<const ConvexPolyhedron>(*pieces, &piece));
    masses.push_back(physics::PolyhedronMassProperties(options_.default_density, piece));
  }
  shape.mass_in_shape_frame = physics::CombineMassProperties(masses);
  return shape;
}

// Triangles of a mesh file, shared by every collision element that uses
// the same file at the same scale.
Result<std::shared_ptr<const physics::CollisionMesh>> UrdfMeshes::LoadTriangles(
    const std::string& uri, const Vec3& scale) {
  using Out = Result<std::shared_ptr<const physics::CollisionMesh>>;
  const Key key{uri, scale.x(), scale.y(), scale.z()};
  const auto cached = triangle_meshes_.find(key);
  if (cached != triangle_meshes_.end()) return cached->second;
  Out built = Out::Error("");
  if (options_.mesh_triangles_loader) {
    const Result<std::string> path = resolver_(uri);
    if (!path.ok()) return Out::Error("mesh " + Quoted(uri) + ": " + path.message());
    built = options_.mesh_triangles_loader(*path, scale);
  } else {
    Result<physics::TriangleMesh> mesh = LoadMesh(uri, scale, resolver_, options_.max_file_bytes);
    if (!mesh.ok()) return mesh.status();
    built = physics::CollisionMesh::Make(*mesh);
    if (!built.ok()) return Out::Error("mesh " + Quoted(uri) + ": " + built.message());
  }
  if (built.ok()) triangle_meshes_.emplace(key, *built);
  return built;
}

// Hull of a mesh file, shared by every collision element that uses the
// same file at the same scale.
Result<std::shared_ptr<const ConvexPolyhedron>> UrdfMeshes::LoadHull(const std::string& uri,
                                                                     const Vec3& scale) {
  using Out = Result<std::shared_ptr<const ConvexPolyhedron>>;
  const Key key{uri, scale.x(), scale.y(), scale.z()};
  const auto cached = hulls_.find(key);
  if (cached != hulls_.end()) return cached->second;
  Out built = Out::Error("");
  if (options_.mesh_hull_loader) {
    const Result<std::string> path = resolver_(uri);
    if (!path.ok()) return Out::Error("mesh " + Quoted(uri) + ": " + path.message());
    built = options_.mesh_hull_loader(*path, scale, options_.hull);
  } else {
    Result<physics::TriangleMesh> mesh = LoadMesh(uri, scale, resolver_, options_.max_file_bytes);
    if (!mesh.ok()) return mesh.status();
    Result<ConvexPolyhedron> hull = ComputeConvexHull(mesh->vertices, options_.hull);
    if (!hull.ok()) return Out::Error("mesh " + Quoted(uri) + ": " + hull.message());
    built = std::make_shared<const ConvexPolyhedron>(std::move(hull).value());
  }
  if (built.ok()) hulls_.emplace(key, *built);
  return built;
}

// Pieces of a mesh file under a rule, shared likewise. Their hulls keep the
// model's hull options.
Result<std::shared_ptr<const std::vector<ConvexPolyhedron>>> UrdfMeshes::LoadPieces(
    const std::string& uri, const Vec3& scale, PiecesRule rule) {
  using Out = Result<std::shared_ptr<const std::vector<ConvexPolyhedron>>>;
  const auto key = std::make_tuple(Key{uri, scale.x(), scale.y(), scale.z()}, rule);
  const auto cached = pieces_.find(key);
  if (cached != pieces_.end()) return cached->second;
  DecompositionOptions decomposition = options_.decomposition;
  decomposition.hull = options_.hull;
  Out built = Out::Error("");
  if (options_.mesh_pieces_loader) {
    const Result<std::string> path = resolver_(uri);
    if (!path.ok()) return Out::Error("mesh " + Quoted(uri) + ": " + path.message());
    // The loader cannot return the disk cache's warnings (MeshPiecesLoader
    // returns pieces only); they come back through the thread's collector.
    const MeshCacheWarnings cache_warnings;
    built = options_.mesh_pieces_loader(*path, scale, decomposition, rule);
    warnings_.insert(warnings_.end(), cache_warnings.warnings().begin(),
                     cache_warnings.warnings().end());
  } else {
    Result<physics::TriangleMesh> mesh = LoadMesh(uri, scale, resolver_, options_.max_file_bytes);
    if (!mesh.ok()) return mesh.status();
    Result<std::vector<ConvexPolyhedron>> pieces = ConvexPieces(*mesh, decomposition, rule);
    if (!pieces.ok()) return Out::Error("mesh " + Quoted(uri) + ": " + pieces.message());
    built = std::make_shared<const std::vector<ConvexPolyhedron>>(std::move(pieces).value());
  }
  if (built.ok()) pieces_.emplace(key, *built);
  return built;
}

}  // namespace rigid_body_sim::io
