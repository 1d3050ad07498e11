#include "rigid_body_sim/physics/mass_properties.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

namespace rigid_body_sim::physics {
namespace {

// |volume| below this fraction of (bounding-box diagonal)^3 counts as zero:
// such a mesh is flat or self-cancelling, and its inertia would be noise.
constexpr double kRelativeVolumeTolerance = 1e-12;
// Inertia tensors that differ from their transpose by more than this
// fraction of their largest entry are refused as asymmetric.
constexpr double kRelativeSymmetryTolerance = 1e-9;
// Principal moments may violate I1 + I2 >= I3 by this fraction of I3: flat
// plates sit exactly on the bound and inertias read from files carry
// rounding of a few significant digits.
constexpr double kRelativeTriangleTolerance = 1e-6;

// Inertia about the origin from the second moment C = integral of x x^T dm:
// I = trace(C) E - C.
Mat3 InertiaFromSecondMoment(const Mat3& second_moment) {
  return second_moment.trace() * Mat3::Identity() - second_moment;
}

// Parallel-axis (Steiner) term: inertia of a point mass m at offset d,
// m (|d|^2 E - d d^T).
Mat3 PointMassInertia(double mass, const Vec3& offset) {
  return mass * (offset.squaredNorm() * Mat3::Identity() - offset * offset.transpose());
}

std::string FormatMatrix(const Mat3& m) {
  std::ostringstream out;
  out.precision(9);
  out << "[";
  for (int r = 0; r < 3; ++r) {
    out << (r == 0 ? "[" : ", [") << m(r, 0) << ", " << m(r, 1) << ", " << m(r, 2) << "]";
  }
  out << "]";
  return out.str();
}

// Every index in range, no triangle repeats a vertex, and the surface is
// closed: every directed edge (u, v) occurs exactly once and its reverse
// (v, u) occurs too, so the surface has no boundary and is consistently
// oriented.
Status CheckClosedMesh(const TriangleMesh& mesh) {
  const int vertex_count = static_cast<int>(mesh.vertices.size());
  std::vector<std::pair<int, int>> directed_edges;
  directed_edges.reserve(3 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& triangle = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (triangle[k] < 0 || triangle[k] >= vertex_count) {
        return Status::Error("triangle " + std::to_string(t) + " has vertex index " +
                             std::to_string(triangle[k]) + " outside [0, " +
                             std::to_string(vertex_count) + ")");
      }
    }
    if (triangle[0] == triangle[1] || triangle[1] == triangle[2] || triangle[2] == triangle[0]) {
      return Status::Error("triangle " + std::to_string(t) + " repeats a vertex index");
    }
    for (int k = 0; k < 3; ++k) directed_edges.emplace_back(triangle[k], triangle[(k + 1) % 3]);
  }
  std::sort(directed_edges.begin(), directed_edges.end());
  for (std::size_t i = 0; i < directed_edges.size(); ++i) {
    const auto& [from, to] = directed_edges[i];
    if (i + 1 < directed_edges.size() && directed_edges[i + 1] == directed_edges[i]) {
      return Status::Error("triangle mesh is not a 2-manifold: directed edge " +
                           std::to_string(from) + "->" + std::to_string(to) +
                           " is used by more than one triangle");
    }
    if (!std::binary_search(directed_edges.begin(), directed_edges.end(),
                            std::make_pair(to, from))) {
      return Status::Error("triangle mesh is open or inconsistently oriented: edge " +
                           std::to_string(from) + "->" + std::to_string(to) +
                           " has no reverse edge " + std::to_string(to) + "->" +
                           std::to_string(from));
    }
  }

  return Status::Ok();
}

// The mean of the vertices the triangles use (the moments are summed about
// it, to avoid cancellation) and their bounding-box diagonal.
void MeshReference(const TriangleMesh& mesh, Vec3* reference, double* extent) {
  Vec3 lower = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 upper = -lower;
  std::vector<bool> used(mesh.vertices.size(), false);
  int used_count = 0;
  *reference = Vec3::Zero();
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      if (used[triangle[k]]) continue;
      used[triangle[k]] = true;
      ++used_count;
      const Vec3& p = mesh.vertices[triangle[k]];
      *reference += p;
      lower = lower.cwiseMin(p);
      upper = upper.cwiseMax(p);
    }
  }
  *reference /= used_count;
  *extent = (upper - lower).norm();
}

}  // namespace

// Solid box of edge lengths (a, b, c): m = rho a b c,
// I = m/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2).
MassProperties BoxMassProperties(double density, const Vec3& size) {
  MassProperties result;
  result.mass = density * size.x() * size.y() * size.z();
  const Vec3 squared = size.cwiseProduct(size);
  result.inertia_about_com =
      (result.mass / 12.0) *
      Vec3(squared.y() + squared.z(), squared.x() + squared.z(), squared.x() + squared.y())
          .asDiagonal();
  return result;
}

// Solid sphere: m = 4/3 pi r^3 rho, I = 2/5 m r^2 about every axis.
MassProperties SphereMassProperties(double density, double radius) {
  MassProperties result;
  result.mass = density * 4.0 / 3.0 * kPi * radius * radius * radius;
  result.inertia_about_com = (0.4 * result.mass * radius * radius) * Mat3::Identity();
  return result;
}

// Solid cylinder, axis z, centred: m = rho pi r^2 l,
// I_zz = m r^2 / 2, I_xx = I_yy = m (3 r^2 + l^2) / 12.
MassProperties CylinderMassProperties(double density, double radius, double length) {
  MassProperties result;
  result.mass = density * kPi * radius * radius * length;
  const double transverse = result.mass * (3.0 * radius * radius + length * length) / 12.0;
  const double axial = 0.5 * result.mass * radius * radius;
  result.inertia_about_com = Vec3(transverse, transverse, axial).asDiagonal();
  return result;
}

// Volume integrals over a closed mesh by the divergence theorem, evaluated
// as a sum of signed tetrahedra (reference point p, triangle a b c): each
// contributes V = a.(b x c)/6, first moment V (a+b+c)/4 and second moment
// integral of x x^T dV = V/20 (a a^T + b b^T + c c^T + s s^T), s = a+b+c
// (Tonon 2004, "Explicit exact formulas for the 3-D tetrahedron inertia
// tensor in terms of its vertex coordinates"; equivalent to the surface
// integrals of Mirtich 1996). Coordinates are taken relative to the vertex
// mean so that off-origin meshes do not lose digits to cancellation.
// A closed mesh given inside-out (all triangles clockwise) yields a negative
// volume; all integrals then flip sign together, so the sign is divided out
// and the mesh accepted.
Result<MassProperties> TriangleMeshMassProperties(double density, const TriangleMesh& mesh) {
  if (!std::isfinite(density) || density <= 0.0) {
    std::ostringstream out;
    out << "density must be positive and finite, got " << density << " kg/m^3";
    return Result<MassProperties>::Error(out.str());
  }
  if (mesh.triangles.size() < 4) {
    return Result<MassProperties>::Error("triangle mesh has " +
                                         std::to_string(mesh.triangles.size()) +
                                         " triangles; a closed mesh needs at least 4");
  }
  const int vertex_count = static_cast<int>(mesh.vertices.size());
  for (int i = 0; i < vertex_count; ++i) {
    if (!IsFinite(mesh.vertices[i])) {
      return Result<MassProperties>::Error("triangle mesh vertex " + std::to_string(i) +
                                           " is not finite");
    }
  }

  if (Status status = CheckClosedMesh(mesh); !status.ok()) return status;
  Vec3 reference;
  double extent = 0.0;
  MeshReference(mesh, &reference, &extent);

  double volume = 0.0;
  Vec3 first_moment = Vec3::Zero();
  Mat3 second_moment = Mat3::Zero();
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    const Vec3 a = mesh.vertices[triangle[0]] - reference;
    const Vec3 b = mesh.vertices[triangle[1]] - reference;
    const Vec3 c = mesh.vertices[triangle[2]] - reference;
    const double tetra_volume = a.dot(b.cross(c)) / 6.0;
    const Vec3 sum = a + b + c;
    volume += tetra_volume;
    first_moment += tetra_volume * sum / 4.0;
    second_moment += (tetra_volume / 20.0) * (a * a.transpose() + b * b.transpose() +
                                              c * c.transpose() + sum * sum.transpose());
  }

  if (!(std::abs(volume) > kRelativeVolumeTolerance * extent * extent * extent)) {
    std::ostringstream out;
    out << "triangle mesh encloses (almost) no volume: " << volume
        << " m^3 for a bounding-box diagonal of " << extent << " m";
    return Result<MassProperties>::Error(out.str());
  }
  if (volume < 0.0) {
    volume = -volume;
    first_moment = -first_moment;
    second_moment = -second_moment;
  }

  const Vec3 com_from_reference = first_moment / volume;
  // Second moment about the centre of mass: C_com = C - V c c^T.
  const Mat3 second_moment_com =
      second_moment - volume * com_from_reference * com_from_reference.transpose();

  MassProperties result;
  result.mass = density * volume;
  result.center_of_mass = reference + com_from_reference;
  result.inertia_about_com = density * InertiaFromSecondMoment(second_moment_com);
  // Exact symmetry; the sum above is symmetric up to rounding only.
  result.inertia_about_com =
      0.5 * (result.inertia_about_com + result.inertia_about_com.transpose()).eval();
  return result;
}

// Rigid change of frame: c' = R c + t, I' = R I R^T (inertia about the
// centre of mass does not depend on where the centre is).
MassProperties TransformMassProperties(const MassProperties& part, const Pose& frame_from_part) {
  const Mat3 rotation = frame_from_part.rotation.normalized().toRotationMatrix();
  MassProperties result;
  result.mass = part.mass;
  result.center_of_mass = rotation * part.center_of_mass + frame_from_part.translation;
  result.inertia_about_com = rotation * part.inertia_about_com * rotation.transpose();
  return result;
}

// Sum of parts: M = sum m_i, c = sum m_i c_i / M,
// I = sum (I_i + m_i (|d_i|^2 E - d_i d_i^T)), d_i = c_i - c (parallel-axis
// theorem, Steiner). An empty list or zero total mass gives zero properties,
// which ValidateMassProperties refuses.
MassProperties CombineMassProperties(const std::vector<MassProperties>& parts) {
  MassProperties result;
  Vec3 weighted_com = Vec3::Zero();
  for (const MassProperties& part : parts) {
    result.mass += part.mass;
    weighted_com += part.mass * part.center_of_mass;
  }
  if (result.mass == 0.0) return MassProperties{};
  result.center_of_mass = weighted_com / result.mass;
  for (const MassProperties& part : parts) {
    result.inertia_about_com +=
        part.inertia_about_com +
        PointMassInertia(part.mass, part.center_of_mass - result.center_of_mass);
  }
  return result;
}

// Eigen decomposition I = R diag(lambda) R^T of the symmetric part of the
// tensor (Eigen::SelfAdjointEigenSolver, eigenvalues ascending). If the
// eigenvector basis is left-handed, one axis is negated, which keeps R an
// eigenbasis and makes it a proper rotation.
PrincipalAxes ComputePrincipalAxes(const Mat3& inertia_about_com) {
  const Mat3 symmetric = 0.5 * (inertia_about_com + inertia_about_com.transpose());
  const Eigen::SelfAdjointEigenSolver<Mat3> solver(symmetric);
  Mat3 body_from_principal = solver.eigenvectors();
  if (body_from_principal.determinant() < 0.0) {
    body_from_principal.col(2) = -body_from_principal.col(2);
  }
  PrincipalAxes result;
  result.principal_moments = solver.eigenvalues();
  result.body_from_principal = Quat(body_from_principal).normalized();
  return result;
}

Status ValidateMassProperties(const MassProperties& mass_properties) {
  std::ostringstream out;
  out.precision(9);
  if (!std::isfinite(mass_properties.mass) || mass_properties.mass <= 0.0) {
    out << "mass must be positive and finite, got " << mass_properties.mass << " kg";
    return Status::Error(out.str());
  }
  if (!IsFinite(mass_properties.center_of_mass)) {
    out << "centre of mass is not finite: [" << mass_properties.center_of_mass.transpose() << "]";
    return Status::Error(out.str());
  }
  const Mat3& inertia = mass_properties.inertia_about_com;
  if (!inertia.allFinite()) {
    out << "inertia tensor is not finite: " << FormatMatrix(inertia);
    return Status::Error(out.str());
  }
  const double asymmetry = (inertia - inertia.transpose()).cwiseAbs().maxCoeff();
  const double largest = inertia.cwiseAbs().maxCoeff();
  if (asymmetry > kRelativeSymmetryTolerance * largest) {
    out << "inertia tensor is not symmetric: largest |I - I^T| entry " << asymmetry
        << " kg m^2 for largest entry " << largest << " kg m^2, tensor " << FormatMatrix(inertia);
    return Status::Error(out.str());
  }
  const Vec3 moments = ComputePrincipalAxes(inertia).principal_moments;
  if (!(moments[0] > 0.0)) {
    out << "inertia tensor is not positive definite: principal moments [" << moments.transpose()
        << "] kg m^2, tensor " << FormatMatrix(inertia);
    return Status::Error(out.str());
  }
  if (moments[0] + moments[1] < moments[2] * (1.0 - kRelativeTriangleTolerance)) {
    out << "principal moments violate the triangle inequality I1 + I2 >= I3: " << moments[0]
        << " + " << moments[1] << " < " << moments[2] << " kg m^2";
    return Status::Error(out.str());
  }
  return Status::Ok();
}

}  // namespace rigid_body_sim::physics
