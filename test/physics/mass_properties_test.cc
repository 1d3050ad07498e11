#include "rigid_body_sim/physics/mass_properties.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mesh_fixtures.h"

namespace rigid_body_sim::physics {
namespace {

using testing::BoxMesh;
using testing::Contains;
using testing::CylinderMesh;
using testing::Icosphere;
using testing::PrismMassProperties;
using testing::RelativeDifference;

Mat3 RandomRotation(std::mt19937& random) {
  std::normal_distribution<double> normal;
  return Quat(normal(random), normal(random), normal(random), normal(random))
      .normalized()
      .toRotationMatrix();
}

TEST(MassPropertiesTest, BoxMatchesClosedForm) {
  const double density = 7800.0;
  const Vec3 size(0.3, 0.5, 1.1);
  const MassProperties box = BoxMassProperties(density, size);
  const double mass = 7800.0 * 0.3 * 0.5 * 1.1;
  EXPECT_NEAR(box.mass, mass, 1e-12 * mass);
  EXPECT_EQ(box.center_of_mass, Vec3::Zero());
  const Mat3 expected =
      Vec3(mass * (0.25 + 1.21) / 12.0, mass * (0.09 + 1.21) / 12.0, mass * (0.09 + 0.25) / 12.0)
          .asDiagonal();
  EXPECT_LT(RelativeDifference(box.inertia_about_com, expected), 1e-12);
}

TEST(MassPropertiesTest, BoxMeshIsExact) {
  const Vec3 size(0.3, 0.5, 1.1);
  const Result<MassProperties> mesh = TriangleMeshMassProperties(7800.0, BoxMesh(size));
  ASSERT_TRUE(mesh.ok()) << mesh.message();
  const MassProperties box = BoxMassProperties(7800.0, size);
  EXPECT_NEAR(mesh->mass, box.mass, 1e-12 * box.mass);
  EXPECT_LT(mesh->center_of_mass.norm(), 1e-12);
  EXPECT_LT(RelativeDifference(mesh->inertia_about_com, box.inertia_about_com), 1e-12);
}

TEST(MassPropertiesTest, IcosphereApproachesSphere) {
  const double density = 1000.0;
  const double radius = 0.7;
  const TriangleMesh mesh = Icosphere(radius, 4);
  ASSERT_EQ(mesh.triangles.size(), 5120u);
  const Result<MassProperties> sphere_mesh = TriangleMeshMassProperties(density, mesh);
  ASSERT_TRUE(sphere_mesh.ok()) << sphere_mesh.message();
  const MassProperties sphere = SphereMassProperties(density, radius);
  EXPECT_NEAR(sphere.mass, density * 4.0 / 3.0 * kPi * std::pow(radius, 3), 1e-12 * sphere.mass);
  EXPECT_NEAR(sphere.inertia_about_com(0, 0), 0.4 * sphere.mass * radius * radius,
              1e-12 * sphere.mass);
  // An inscribed polyhedron has slightly less volume than the sphere.
  EXPECT_LT(sphere_mesh->mass, sphere.mass);
  EXPECT_NEAR(sphere_mesh->mass, sphere.mass, 0.01 * sphere.mass);
  EXPECT_LT(sphere_mesh->center_of_mass.norm(), 1e-12 * radius);
  EXPECT_LT(RelativeDifference(sphere_mesh->inertia_about_com, sphere.inertia_about_com), 0.01);
  // Icosahedral symmetry makes the inertia exactly isotropic.
  const Mat3 isotropic = sphere_mesh->inertia_about_com(0, 0) * Mat3::Identity();
  EXPECT_LT(RelativeDifference(sphere_mesh->inertia_about_com, isotropic), 1e-12);
}

TEST(MassPropertiesTest, CylinderMeshMatchesPrismExactlyAndCylinderWithinOnePercent) {
  const double density = 2700.0;
  const double radius = 0.2;
  const double length = 0.9;
  const int segments = 96;
  const Result<MassProperties> mesh =
      TriangleMeshMassProperties(density, CylinderMesh(radius, length, segments));
  ASSERT_TRUE(mesh.ok()) << mesh.message();

  const MassProperties prism = PrismMassProperties(density, radius, length, segments);
  EXPECT_NEAR(mesh->mass, prism.mass, 1e-12 * prism.mass);
  EXPECT_LT(mesh->center_of_mass.norm(), 1e-12);
  EXPECT_LT(RelativeDifference(mesh->inertia_about_com, prism.inertia_about_com), 1e-12);

  const MassProperties cylinder = CylinderMassProperties(density, radius, length);
  EXPECT_NEAR(cylinder.mass, density * kPi * radius * radius * length, 1e-12 * cylinder.mass);
  EXPECT_NEAR(mesh->mass, cylinder.mass, 0.01 * cylinder.mass);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(mesh->inertia_about_com(k, k), cylinder.inertia_about_com(k, k),
                0.01 * cylinder.inertia_about_com(k, k));
  }
}

TEST(MassPropertiesTest, OffCentreRotatedBoxMesh) {
  const double density = 1200.0;
  const Vec3 size(0.4, 1.3, 0.25);
  Pose world_from_box;
  world_from_box.translation = Vec3(3.0, -2.0, 5.5);
  world_from_box.rotation = Quat(Eigen::AngleAxisd(0.7, Vec3(1.0, -2.0, 0.5).normalized()));
  TriangleMesh mesh = BoxMesh(size);
  for (Vec3& vertex : mesh.vertices) vertex = world_from_box * vertex;

  const Result<MassProperties> moved = TriangleMeshMassProperties(density, mesh);
  ASSERT_TRUE(moved.ok()) << moved.message();
  const MassProperties box = BoxMassProperties(density, size);
  const Mat3 rotation = world_from_box.rotation.toRotationMatrix();
  const Mat3 expected_inertia = rotation * box.inertia_about_com * rotation.transpose();
  EXPECT_NEAR(moved->mass, box.mass, 1e-12 * box.mass);
  EXPECT_LT((moved->center_of_mass - world_from_box.translation).norm(), 1e-9);
  EXPECT_LT(RelativeDifference(moved->inertia_about_com, expected_inertia), 1e-12);

  const MassProperties transformed = TransformMassProperties(box, world_from_box);
  EXPECT_EQ(transformed.mass, box.mass);
  EXPECT_LT((transformed.center_of_mass - world_from_box.translation).norm(), 1e-15);
  EXPECT_LT(RelativeDifference(transformed.inertia_about_com, expected_inertia), 1e-14);
}

TEST(MassPropertiesTest, InsideOutMeshGivesSameProperties) {
  TriangleMesh mesh = BoxMesh(Vec3(1.0, 2.0, 3.0));
  const Result<MassProperties> outward = TriangleMeshMassProperties(10.0, mesh);
  for (Eigen::Vector3i& triangle : mesh.triangles) std::swap(triangle[1], triangle[2]);
  const Result<MassProperties> inward = TriangleMeshMassProperties(10.0, mesh);
  ASSERT_TRUE(outward.ok() && inward.ok());
  EXPECT_NEAR(inward->mass, 60.0, 1e-12);
  EXPECT_NEAR(inward->mass, outward->mass, 1e-12);
  EXPECT_LT(RelativeDifference(inward->inertia_about_com, outward->inertia_about_com), 1e-14);
}

// Splitting a box along x at a fraction s into boxes of lengths s a and
// (1 - s) a, each centred on its own half, and combining them with the
// parallel-axis theorem must give the whole box.
TEST(MassPropertiesTest, CombiningTwoPartsOfABoxGivesTheBox) {
  const double density = 500.0;
  const Vec3 size(1.2, 0.4, 0.7);
  const Vec3 centre(0.3, -0.1, 2.0);
  for (double fraction : {0.5, 0.3}) {
    const double left_length = fraction * size.x();
    const double right_length = size.x() - left_length;
    MassProperties left = BoxMassProperties(density, Vec3(left_length, size.y(), size.z()));
    MassProperties right = BoxMassProperties(density, Vec3(right_length, size.y(), size.z()));
    left.center_of_mass = centre + Vec3(-0.5 * size.x() + 0.5 * left_length, 0.0, 0.0);
    right.center_of_mass = centre + Vec3(0.5 * size.x() - 0.5 * right_length, 0.0, 0.0);

    const MassProperties combined = CombineMassProperties({left, right});
    const MassProperties whole = BoxMassProperties(density, size);
    EXPECT_NEAR(combined.mass, whole.mass, 1e-12 * whole.mass);
    EXPECT_LT((combined.center_of_mass - centre).norm(), 1e-12);
    EXPECT_LT(RelativeDifference(combined.inertia_about_com, whole.inertia_about_com), 1e-12);
  }
}

TEST(MassPropertiesTest, CombiningRotatedPartsMatchesMeshOfTheUnion) {
  // Two unit cubes side by side, the pair rotated: the union is a 2x1x1 box.
  Pose frame_from_pair;
  frame_from_pair.rotation = Quat(Eigen::AngleAxisd(1.1, Vec3(0.3, 0.4, -0.8).normalized()));
  frame_from_pair.translation = Vec3(-1.0, 0.5, 0.25);
  MassProperties left = BoxMassProperties(3.0, Vec3::Ones());
  MassProperties right = left;
  left.center_of_mass = Vec3(-0.5, 0.0, 0.0);
  right.center_of_mass = Vec3(0.5, 0.0, 0.0);
  const MassProperties combined =
      CombineMassProperties({TransformMassProperties(left, frame_from_pair),
                             TransformMassProperties(right, frame_from_pair)});
  const MassProperties expected =
      TransformMassProperties(BoxMassProperties(3.0, Vec3(2.0, 1.0, 1.0)), frame_from_pair);
  EXPECT_NEAR(combined.mass, 6.0, 1e-12);
  EXPECT_LT((combined.center_of_mass - expected.center_of_mass).norm(), 1e-12);
  EXPECT_LT(RelativeDifference(combined.inertia_about_com, expected.inertia_about_com), 1e-12);
}

TEST(MassPropertiesTest, PrincipalAxesOfRotatedBoxes) {
  std::mt19937 random(7);
  const MassProperties box = BoxMassProperties(900.0, Vec3(0.5, 0.9, 0.2));
  // The box axes, ordered by ascending moment.
  const Vec3 moments = box.inertia_about_com.diagonal();
  std::vector<int> axis_order = {0, 1, 2};
  std::sort(axis_order.begin(), axis_order.end(),
            [&](int a, int b) { return moments[a] < moments[b]; });
  for (int trial = 0; trial < 50; ++trial) {
    const Mat3 body_from_box = RandomRotation(random);
    const Mat3 inertia = body_from_box * box.inertia_about_com * body_from_box.transpose();
    const PrincipalAxes axes = ComputePrincipalAxes(inertia);
    const Mat3 body_from_principal = axes.body_from_principal.toRotationMatrix();
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(axes.principal_moments[k], moments[axis_order[k]], 1e-12 * moments.maxCoeff());
      // The k-th principal axis is the box axis with that moment, up to sign.
      EXPECT_NEAR(std::abs(body_from_principal.col(k).dot(body_from_box.col(axis_order[k]))), 1.0,
                  1e-12);
    }
    EXPECT_NEAR(body_from_principal.determinant(), 1.0, 1e-12);
    EXPECT_LT((body_from_principal.transpose() * body_from_principal - Mat3::Identity())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-12);
    const Mat3 rebuilt =
        body_from_principal * axes.principal_moments.asDiagonal() * body_from_principal.transpose();
    EXPECT_LT(RelativeDifference(rebuilt, inertia), 1e-12);
  }
}

TEST(MassPropertiesTest, ValidateAcceptsPhysicalProperties) {
  EXPECT_TRUE(ValidateMassProperties(BoxMassProperties(1.0, Vec3(1.0, 2.0, 3.0))).ok());
  // A thin plate sits on the triangle-inequality bound I3 = I1 + I2.
  MassProperties plate;
  plate.mass = 2.0;
  plate.inertia_about_com = Vec3(1.0, 2.0, 3.0).asDiagonal();
  EXPECT_TRUE(ValidateMassProperties(plate).ok()) << ValidateMassProperties(plate).message();
}

TEST(MassPropertiesTest, ValidateRefusesUnphysicalProperties) {
  const MassProperties good = BoxMassProperties(1.0, Vec3(1.0, 2.0, 3.0));

  MassProperties zero_mass = good;
  zero_mass.mass = 0.0;
  EXPECT_TRUE(Contains(ValidateMassProperties(zero_mass).message(), "mass must be positive"));
  MassProperties negative_mass = good;
  negative_mass.mass = -1.0;
  EXPECT_TRUE(Contains(ValidateMassProperties(negative_mass).message(), "-1 kg"));
  MassProperties nan_mass = good;
  nan_mass.mass = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(Contains(ValidateMassProperties(nan_mass).message(), "mass must be positive"));

  MassProperties nan_com = good;
  nan_com.center_of_mass.y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(Contains(ValidateMassProperties(nan_com).message(), "centre of mass"));
  MassProperties nan_inertia = good;
  nan_inertia.inertia_about_com(1, 2) = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(Contains(ValidateMassProperties(nan_inertia).message(), "not finite"));

  MassProperties asymmetric = good;
  asymmetric.inertia_about_com(0, 1) = 0.01;
  EXPECT_TRUE(Contains(ValidateMassProperties(asymmetric).message(), "not symmetric"));

  MassProperties indefinite = good;
  indefinite.inertia_about_com = Vec3(1.0, 2.0, -0.5).asDiagonal();
  EXPECT_TRUE(Contains(ValidateMassProperties(indefinite).message(), "not positive definite"));
  MassProperties singular = good;
  singular.inertia_about_com = Vec3(1.0, 1.0, 0.0).asDiagonal();
  EXPECT_TRUE(Contains(ValidateMassProperties(singular).message(), "not positive definite"));

  // Off-diagonal so the violation only shows in the principal moments:
  // rotate diag(1, 1, 2.5) (1 + 1 < 2.5).
  MassProperties triangle = good;
  const Mat3 rotation = Eigen::AngleAxisd(0.4, Vec3(1.0, 1.0, 0.0).normalized()).toRotationMatrix();
  triangle.inertia_about_com = rotation * Vec3(1.0, 1.0, 2.5).asDiagonal() * rotation.transpose();
  const Status refused = ValidateMassProperties(triangle);
  EXPECT_TRUE(Contains(refused.message(), "triangle inequality"));
  EXPECT_TRUE(Contains(refused.message(), "2.5"));
}

TEST(MassPropertiesTest, RefusesBadMeshes) {
  const TriangleMesh box = BoxMesh(Vec3(1.0, 1.0, 1.0));

  TriangleMesh open = box;
  open.triangles.pop_back();
  EXPECT_TRUE(Contains(TriangleMeshMassProperties(1.0, open).message(), "open"));

  TriangleMesh nan_vertex = box;
  nan_vertex.vertices[3].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(
      Contains(TriangleMeshMassProperties(1.0, nan_vertex).message(), "vertex 3 is not finite"));

  TriangleMesh bad_index = box;
  bad_index.triangles[5][1] = 8;
  EXPECT_TRUE(Contains(TriangleMeshMassProperties(1.0, bad_index).message(),
                       "vertex index 8 outside [0, 8)"));

  TriangleMesh doubled = box;
  doubled.triangles.push_back(box.triangles[0]);
  EXPECT_TRUE(Contains(TriangleMeshMassProperties(1.0, doubled).message(), "2-manifold"));

  // A closed, consistently oriented but flat surface: a square seen from
  // above split along one diagonal, from below along the other.
  TriangleMesh flat;
  flat.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  flat.triangles = {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(0, 2, 3), Eigen::Vector3i(1, 0, 3),
                    Eigen::Vector3i(1, 3, 2)};
  EXPECT_TRUE(Contains(TriangleMeshMassProperties(1.0, flat).message(), "no volume"));

  EXPECT_TRUE(Contains(TriangleMeshMassProperties(0.0, box).message(), "density"));
  EXPECT_TRUE(
      Contains(TriangleMeshMassProperties(std::numeric_limits<double>::quiet_NaN(), box).message(),
               "density"));
}

}  // namespace
}  // namespace rigid_body_sim::physics
