// The collision shapes of a URDF <mesh>: its triangles (static models), its
// convex hull, or its convex pieces (moving models' concave meshes), each
// file read once per model at each scale.
#ifndef RIGID_BODY_SIM_IO_URDF_MESHES_H_
#define RIGID_BODY_SIM_IO_URDF_MESHES_H_

#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "rigid_body_sim/io/convex_decomposition.h"
#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/shape.h"

namespace rigid_body_sim::io {

// One collision element's geometry, several convex shapes for a
// decomposed mesh, all in the element's frame, and their mass properties
// there at the default density.
struct ShapeWithMass {
  std::vector<physics::ShapeGeometry> geometry;
  physics::MassProperties mass_in_shape_frame;
};

class UrdfMeshes {
 public:
  UrdfMeshes(const UrdfLoadOptions& options, UriResolver resolver)
      : options_(options), resolver_(std::move(resolver)) {}

  // Largest size over smallest allowed of a hull or piece (MaxAspectRatio
  // of the model being built).
  void set_max_aspect_ratio(double ratio) { max_aspect_ratio_ = ratio; }

  // A static mesh that collides as its triangles. Its mass (for the link
  // mass that GetModelProperties reports) is that of the solid it bounds
  // when it is closed, else zero; a static model has no dynamics.
  physics::Result<ShapeWithMass> Triangles(const std::string& uri, const physics::Vec3& scale,
                                           const std::string& where);
  // The mesh's convex hull.
  physics::Result<ShapeWithMass> Hull(const std::string& uri, const physics::Vec3& scale,
                                      const std::string& where);
  // The mesh's convex pieces (ConvexPieces under `rule`); their mass is the
  // sum of the pieces' at the default density.
  physics::Result<ShapeWithMass> Pieces(const std::string& uri, const physics::Vec3& scale,
                                        PiecesRule rule, const std::string& where);

  // What the pieces loader's disk cache warned about (MeshCacheWarnings),
  // for the model's warnings.
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  using Key = std::tuple<std::string, double, double, double>;
  physics::Result<std::shared_ptr<const physics::CollisionMesh>> LoadTriangles(
      const std::string& uri, const physics::Vec3& scale);
  physics::Result<std::shared_ptr<const physics::ConvexPolyhedron>> LoadHull(
      const std::string& uri, const physics::Vec3& scale);
  physics::Result<std::shared_ptr<const std::vector<physics::ConvexPolyhedron>>> LoadPieces(
      const std::string& uri, const physics::Vec3& scale, PiecesRule rule);

  const UrdfLoadOptions& options_;
  UriResolver resolver_;
  double max_aspect_ratio_ = kMaxShapeAspectRatio;
  std::map<Key, std::shared_ptr<const physics::CollisionMesh>> triangle_meshes_;
  std::map<Key, std::shared_ptr<const physics::ConvexPolyhedron>> hulls_;
  std::map<std::tuple<Key, PiecesRule>,
           std::shared_ptr<const std::vector<physics::ConvexPolyhedron>>>
      pieces_;
  std::vector<std::string> warnings_;
};

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_URDF_MESHES_H_
