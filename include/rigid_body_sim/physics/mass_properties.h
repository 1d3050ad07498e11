// Mass properties of solid shapes of uniform density, and their combination.
#ifndef RIGID_BODY_SIM_PHYSICS_MASS_PROPERTIES_H_
#define RIGID_BODY_SIM_PHYSICS_MASS_PROPERTIES_H_

#include <vector>

#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// Mass, centre of mass and inertia tensor of a body, all expressed in the
// frame the shapes were given in (the body frame, e.g. a URDF link frame).
struct MassProperties {
  double mass = 0.0;                      // kg
  Vec3 center_of_mass = Vec3::Zero();     // m, in the body frame
  Mat3 inertia_about_com = Mat3::Zero();  // kg m^2, about the centre of mass, body-frame axes
};

// The inertia tensor diagonalised: inertia_about_com =
// R diag(principal_moments) R^T with R = body_from_principal.
struct PrincipalAxes {
  Vec3 principal_moments = Vec3::Zero();  // kg m^2, ascending
  Quat body_from_principal = Quat::Identity();
};

// A closed, outward-oriented (counter-clockwise seen from outside) triangle mesh.
struct TriangleMesh {
  std::vector<Vec3> vertices;              // m
  std::vector<Eigen::Vector3i> triangles;  // indices into vertices
};

MassProperties BoxMassProperties(double density, const Vec3& size);  // size: full edge lengths, m
MassProperties SphereMassProperties(double density, double radius);  // kg/m^3, m
MassProperties CylinderMassProperties(double density, double radius, double length);  // axis = z

// Exact volume integrals over a closed triangle mesh by the divergence
// theorem, summed as signed tetrahedra (Tonon 2004; equivalent to Mirtich
// 1996, "Fast and Accurate Computation of Polyhedral Mass Properties").
// Fails on an open mesh, bad indices, non-finite vertices, non-positive
// density or a degenerate (zero-volume) mesh. An inside-out mesh (clockwise
// triangles) is accepted: its negative volume is flipped.
Result<MassProperties> TriangleMeshMassProperties(double density, const TriangleMesh& mesh);

// Mass properties of `part` seen from another frame: frame_from_part maps the
// part's frame into the target frame.
MassProperties TransformMassProperties(const MassProperties& part, const Pose& frame_from_part);

// Sum of parts given in one frame (parallel-axis theorem).
MassProperties CombineMassProperties(const std::vector<MassProperties>& parts);

PrincipalAxes ComputePrincipalAxes(const Mat3& inertia_about_com);

// Checks mass > 0, everything finite, inertia symmetric positive definite and
// the triangle inequality of principal moments (I1 + I2 >= I3).
Status ValidateMassProperties(const MassProperties& mass_properties);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_MASS_PROPERTIES_H_
