#include "rigid_body_sim/io/mesh_loader.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "polyhedron_checks.h"
#include "rigid_body_sim/io/convex_hull.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/mass_properties.h"

namespace rigid_body_sim::io {
namespace {

using physics::Result;
using physics::TriangleMesh;
using physics::Vec3;

const std::string kDataDir = RBS_TEST_DATA_DIR;

// The shape of test/data/make_test_meshes.py: a 0.5 x 0.25 x 0.125 m box
// with its (+x, +y, +z) corner cut 0.125, 0.0625 and 0.03125 m deep.
const Vec3 kHalf(0.25, 0.125, 0.0625);
const Vec3 kCut(0.125, 0.0625, 0.03125);
const double kVolume = 8.0 * kHalf.prod() - kCut.prod() / 6.0;

std::vector<Vec3> ReferenceVertices() {
  std::vector<Vec3> vertices;
  for (int i = 0; i < 7; ++i) {  // every corner but (+, +, +)
    vertices.emplace_back(i & 4 ? kHalf.x() : -kHalf.x(), i & 2 ? kHalf.y() : -kHalf.y(),
                          i & 1 ? kHalf.z() : -kHalf.z());
  }
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 cut_point = kHalf;
    cut_point[axis] -= kCut[axis];
    vertices.push_back(cut_point);
  }
  return vertices;
}

// Each reference vertex has a hull vertex within `tolerance` and the counts agree.
void ExpectSameVertices(const std::vector<Vec3>& actual, const std::vector<Vec3>& expected,
                        double tolerance) {
  ASSERT_EQ(actual.size(), expected.size());
  for (const Vec3& want : expected) {
    double nearest = 1e300;
    for (const Vec3& have : actual) nearest = std::min(nearest, (have - want).norm());
    EXPECT_LE(nearest, tolerance) << "missing vertex " << want.transpose();
  }
}

class MeshFormatTest : public ::testing::TestWithParam<const char*> {};

// Every format holds the same shape: the mesh is closed and outward (its
// signed volume is the analytic volume), and its hull has the 10 vertices
// and 7 faces of the chamfered box.
TEST_P(MeshFormatTest, LoadsTheChamferedBox) {
  const std::string path = kDataDir + "/" + GetParam();
  const Result<TriangleMesh> mesh = LoadMesh(path);
  ASSERT_TRUE(mesh.ok()) << mesh.message();
  EXPECT_EQ(mesh->vertices.size(), 10u);   // identical vertices joined across sub-meshes
  EXPECT_EQ(mesh->triangles.size(), 16u);  // 4 quads, 2 pentagons and a triangle
  const Result<physics::MassProperties> mass = physics::TriangleMeshMassProperties(1.0, *mesh);
  ASSERT_TRUE(mass.ok()) << mass.message();
  EXPECT_NEAR(mass->mass, kVolume, 1e-12);

  const Result<physics::ConvexPolyhedron> hull = ComputeConvexHull(mesh->vertices);
  ASSERT_TRUE(hull.ok()) << hull.message();
  EXPECT_EQ(hull->faces.size(), 7u);
  ExpectSameVertices(hull->vertices, ReferenceVertices(), 1e-7);
  EXPECT_NEAR(physics::PolyhedronMassProperties(1.0, *hull).mass, kVolume, 1e-12);
  testing::ExpectValidConvexPolyhedron(*hull, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(AllFormats, MeshFormatTest,
                         ::testing::Values("chamfered_box_ascii.stl", "chamfered_box_binary.stl",
                                           "chamfered_box.obj", "chamfered_box.ply",
                                           "chamfered_box_zup.dae", "chamfered_box_yup_cm.dae"));

// The Y_UP centimetre DAE stores 100 * (x, z, -y); loading must undo both.
TEST(MeshLoaderTest, DaeUnitAndUpAxisGiveMetresWithZUp) {
  const Result<TriangleMesh> yup = LoadMesh(kDataDir + "/chamfered_box_yup_cm.dae");
  const Result<TriangleMesh> zup = LoadMesh(kDataDir + "/chamfered_box_zup.dae");
  ASSERT_TRUE(yup.ok()) << yup.message();
  ASSERT_TRUE(zup.ok()) << zup.message();
  ExpectSameVertices(yup->vertices, ReferenceVertices(), 1e-7);
  ExpectSameVertices(zup->vertices, ReferenceVertices(), 1e-7);
}

TEST(MeshLoaderTest, ScaleIsAppliedAndMirroringKeepsTrianglesOutward) {
  const Vec3 scale(2.0, 3.0, -0.5);
  const Result<TriangleMesh> mesh = LoadMesh(kDataDir + "/chamfered_box.obj", scale);
  ASSERT_TRUE(mesh.ok()) << mesh.message();
  std::vector<Vec3> expected;
  for (const Vec3& vertex : ReferenceVertices()) expected.push_back(vertex.cwiseProduct(scale));
  ExpectSameVertices(mesh->vertices, expected, 1e-12);
  const Result<physics::MassProperties> mass = physics::TriangleMeshMassProperties(1.0, *mesh);
  ASSERT_TRUE(mass.ok()) << mass.message();
  EXPECT_NEAR(mass->mass, kVolume * 3.0, 1e-12);  // |det scale| = 3
}

TEST(MeshLoaderTest, ResolvesFileAndPackageUris) {
  EXPECT_TRUE(LoadMesh("file://" + kDataDir + "/chamfered_box.ply").ok());

  const UriResolver resolver = [](const std::string& uri) -> Result<std::string> {
    const std::string prefix = "package://rigid_body_sim/";
    if (uri.rfind(prefix, 0) != 0) return Result<std::string>::Error("unknown package");
    return std::string(RBS_SOURCE_DIR) + "/" + uri.substr(prefix.size());
  };
  const Result<TriangleMesh> mesh =
      LoadMesh("package://rigid_body_sim/test/data/chamfered_box.ply", Vec3::Ones(), resolver);
  ASSERT_TRUE(mesh.ok()) << mesh.message();
  EXPECT_EQ(mesh->vertices.size(), 10u);

  const Result<TriangleMesh> unresolved =
      LoadMesh("package://rigid_body_sim/test/data/chamfered_box.ply");
  ASSERT_FALSE(unresolved.ok());
  EXPECT_NE(unresolved.message().find("package://rigid_body_sim/test/data/chamfered_box.ply"),
            std::string::npos)
      << unresolved.message();
}

// Each refusal names the offending file and the problem.
TEST(MeshLoaderTest, BadFilesAreRefusedNamingTheFile) {
  struct Case {
    std::string file;
    std::string problem;
  };
  const std::vector<Case> cases = {
      {"missing.stl", "does not exist"},
      {"chamfered_box.off", "unsupported format '.off'"},
      {"empty.stl", "empty.stl"},
      {"nan_vertex.stl", "not finite"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const Result<TriangleMesh> mesh = LoadMesh(kDataDir + "/" + c.file);
    ASSERT_FALSE(mesh.ok());
    EXPECT_NE(mesh.message().find(kDataDir + "/" + c.file), std::string::npos) << mesh.message();
    EXPECT_NE(mesh.message().find(c.problem), std::string::npos) << mesh.message();
  }
  const Result<TriangleMesh> flat = LoadMesh(kDataDir + "/chamfered_box.obj", Vec3(1.0, 0.0, 1.0));
  ASSERT_FALSE(flat.ok());
  EXPECT_NE(flat.message().find("scale"), std::string::npos) << flat.message();
}

std::string WriteFile(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// Assimp keeps coordinates as float; OBJ and ASCII STL are read as written,
// to the nearest double, so a terrain's ray hits and contacts can be checked
// against the file's own numbers.
TEST(MeshLoaderTest, TextMeshesKeepTheirDecimalsToTheDouble) {
  const std::vector<Vec3> written = {Vec3(0.1, -2.7182818284590451, 0.30000001),
                                     Vec3(10.000000001, 0.2, -0.3), Vec3(1e-9, 3.3, 7.123456789)};
  ASSERT_NE(static_cast<double>(static_cast<float>(written[0].x())), written[0].x());
  const std::string decimals[3] = {"0.1 -2.7182818284590451 0.30000001", "10.000000001 0.2 -0.3",
                                   "1e-9 3.3 7.123456789"};
  const std::string obj =
      WriteFile("decimals.obj", "# one triangle\nv " + decimals[0] + "\nv " + decimals[1] + "\nv " +
                                    decimals[2] + "\nvt 0 0\nvn 0 0 1\ng part\nf 1/1/1 2//1 -1\n");
  const std::string stl =
      WriteFile("decimals.stl", "solid t\n facet normal 0 0 1\n  outer loop\n   vertex " +
                                    decimals[0] + "\n   vertex " + decimals[1] + "\n   vertex " +
                                    decimals[2] + "\n  endloop\n endfacet\nendsolid t\n");
  for (const std::string& path : {obj, stl}) {
    SCOPED_TRACE(path);
    const Result<TriangleMesh> mesh = LoadMesh(path);
    ASSERT_TRUE(mesh.ok()) << mesh.message();
    ASSERT_EQ(mesh->vertices.size(), 3u);
    ASSERT_EQ(mesh->triangles.size(), 1u);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(mesh->vertices[mesh->triangles[0][k]], written[k]) << "corner " << k;
    }
  }
}

// Polygons become fans from their first corner, points and lines go, and
// vertices no face uses are dropped, as assimp's triangulation does.
TEST(MeshLoaderTest, ObjPolygonsBecomeFansOverTheVerticesTheyUse) {
  const std::string path = WriteFile("polygons.obj",
                                     "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nv 0 0 1\n"
                                     "f 1 2 3 4\nl 1 5\np 5\nf -6 -3 -1\n");
  const Result<TriangleMesh> mesh = LoadMesh(path);
  ASSERT_TRUE(mesh.ok()) << mesh.message();
  EXPECT_EQ(mesh->vertices.size(), 5u);  // (5, 5, 5) only in a line and a point
  ASSERT_EQ(mesh->triangles.size(), 3u);
  double area_z = 0.0;  // of the unit square's two triangles, both facing +z
  for (int t = 0; t < 2; ++t) {
    const Eigen::Vector3i& tri = mesh->triangles[t];
    const Vec3& a = mesh->vertices[tri[0]];
    area_z += 0.5 * (mesh->vertices[tri[1]] - a).cross(mesh->vertices[tri[2]] - a).z();
  }
  EXPECT_DOUBLE_EQ(area_z, 1.0);
}

// An L-shaped face listed from a reflex corner: a fan from there would
// reach outside it, so the file is left to assimp's ear clipping, and the
// triangles cover the L (area 3) once.
TEST(MeshLoaderTest, ConcaveObjFaceIsCoveredOnce) {
  const std::string path = WriteFile(
      "l_shape.obj", "v 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\nf 1 2 3 4 5 6\n");
  const Result<TriangleMesh> mesh = LoadMesh(path);
  ASSERT_TRUE(mesh.ok()) << mesh.message();
  ASSERT_EQ(mesh->triangles.size(), 4u);
  double area = 0.0;
  for (const Eigen::Vector3i& tri : mesh->triangles) {
    const Vec3& a = mesh->vertices[tri[0]];
    const Vec3 normal = (mesh->vertices[tri[1]] - a).cross(mesh->vertices[tri[2]] - a);
    EXPECT_GE(normal.z(), 0.0);
    area += 0.5 * normal.norm();
  }
  EXPECT_NEAR(area, 3.0, 1e-6);
}

}  // namespace
}  // namespace rigid_body_sim::io
