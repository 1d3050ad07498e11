// Convex pieces out of process: the helper's pieces are the in-process
// pieces to the bit; the disk cache answers a second request with no
// process, keyed by the file's bytes and the settings; a stuck helper is a
// refusal.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "rigid_body_sim/io/convex_decomposition.h"
#include "rigid_body_sim/io/mesh_loader.h"
#include "rigid_body_sim/io/mesh_process.h"
#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"

namespace rigid_body_sim::io {
namespace {

using physics::Result;
using physics::Vec3;

const std::string kDataDir = RBS_TEST_DATA_DIR;

MeshProcessLimits HelperLimits() {
  MeshProcessLimits limits;
  limits.helper_path = RBS_MESH_HELPER;
  return limits;
}

// A fresh directory of this test process's own.
std::filesystem::path TemporaryDirectory(const std::string& name) {
  const std::filesystem::path directory = std::filesystem::temp_directory_path() /
                                          ("rbs_mesh_pieces_test_" + std::to_string(getpid())) /
                                          name;
  std::filesystem::remove_all(directory);
  std::filesystem::create_directories(directory);
  return directory;
}

void ExpectSamePieces(const ConvexPieceList& a, const ConvexPieceList& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].vertices.size(), b[i].vertices.size()) << "piece " << i;
    for (std::size_t v = 0; v < a[i].vertices.size(); ++v) {
      EXPECT_EQ(a[i].vertices[v], b[i].vertices[v]) << "piece " << i << " vertex " << v;
    }
    EXPECT_EQ(a[i].faces.size(), b[i].faces.size()) << "piece " << i;
  }
}

TEST(MeshPiecesTest, HelperPiecesAreTheInProcessPiecesExactly) {
  MeshPiecesRequest request;
  request.path = kDataDir + "/mug.stl";
  const Result<ConvexPieceList> remote = LoadMeshPiecesOutOfProcess(request, HelperLimits());
  ASSERT_TRUE(remote.ok()) << remote.message();
  const Result<physics::TriangleMesh> mesh = LoadMesh(request.path);
  ASSERT_TRUE(mesh.ok()) << mesh.message();
  const auto local = ConvexPieces(*mesh, DecompositionOptions{}, PiecesRule::kAuto);
  ASSERT_TRUE(local.ok()) << local.message();
  EXPECT_GE(remote->size(), 4u);
  ExpectSamePieces(*remote, *local);
}

TEST(MeshPiecesTest, ConvexMeshStaysItsHull) {
  MeshPiecesRequest request;
  request.path = kDataDir + "/chamfered_box_binary.stl";
  const Result<ConvexPieceList> pieces = LoadMeshPiecesOutOfProcess(request, HelperLimits());
  ASSERT_TRUE(pieces.ok()) << pieces.message();
  const Result<physics::ConvexPolyhedron> hull =
      LoadMeshHullOutOfProcess(request.path, Vec3::Ones(), HullOptions(), HelperLimits());
  ASSERT_TRUE(hull.ok()) << hull.message();
  ExpectSamePieces(*pieces, {*hull});
}

TEST(MeshPiecesTest, DiskCacheAnswersWithoutAProcessByContentAndSettings) {
  const std::filesystem::path files = TemporaryDirectory("files");
  MeshPiecesRequest request;
  request.path = (files / "mug.stl").string();
  std::filesystem::copy_file(kDataDir + "/mug.stl", request.path);
  request.cache_directory = (TemporaryDirectory("cache") / "nested").string();
  MeshProcessLimits limits = HelperLimits();
  const Result<ConvexPieceList> first = LoadMeshPiecesOutOfProcess(request, limits);
  ASSERT_TRUE(first.ok()) << first.message();
  ASSERT_EQ(std::distance(std::filesystem::directory_iterator(request.cache_directory),
                          std::filesystem::directory_iterator()),
            1);

  // A helper that cannot start: only the disk cache can answer now, also
  // for a copy of the file under another name and modification time.
  limits.helper_path = "/nonexistent/helper";
  request.path = (files / "renamed.stl").string();
  std::filesystem::copy_file(kDataDir + "/mug.stl", request.path);
  const auto start = std::chrono::steady_clock::now();
  const Result<ConvexPieceList> again = LoadMeshPiecesOutOfProcess(request, limits);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(again.ok()) << again.message();
  ExpectSamePieces(*again, *first);
  EXPECT_LT(ms, 50.0);

  // Other settings, or other bytes, are another entry: the helper must run.
  MeshPiecesRequest other = request;
  other.options.max_concavity = 0.02;
  const Result<ConvexPieceList> other_settings = LoadMeshPiecesOutOfProcess(other, limits);
  ASSERT_FALSE(other_settings.ok());
  EXPECT_NE(other_settings.message().find("cannot be started"), std::string::npos)
      << other_settings.message();
  std::ofstream(request.path, std::ios::app) << ' ';
  EXPECT_FALSE(LoadMeshPiecesOutOfProcess(request, limits).ok());
  std::filesystem::remove_all(files.parent_path());
}

// CPU limit 0.5 s: the wall-time deadline is 2 x 0.5 + 1 = 2 s.
TEST(MeshPiecesTest, StuckHelperIsARefusal) {
  const std::filesystem::path directory = TemporaryDirectory("stuck");
  const std::string script = (directory / "stuck.sh").string();
  std::ofstream(script) << "#!/bin/sh\nexec sleep 30\n";
  std::filesystem::permissions(script, std::filesystem::perms::owner_all);
  MeshProcessLimits limits = HelperLimits();
  limits.helper_path = script;
  limits.cpu_seconds = 0.5;
  MeshPiecesRequest request;
  request.path = kDataDir + "/mug.stl";
  const Result<ConvexPieceList> pieces = LoadMeshPiecesOutOfProcess(request, limits);
  ASSERT_FALSE(pieces.ok());
  EXPECT_NE(pieces.message().find("took longer than 2 s and was killed"), std::string::npos)
      << pieces.message();
  std::filesystem::remove_all(directory.parent_path());
}

TEST(MeshPiecesTest, MalformedPiecesRepliesAreRefused) {
  EXPECT_FALSE(ParsePiecesReply("pieces 0\n", 256).ok());
  EXPECT_FALSE(ParsePiecesReply("pieces 65\n", 256).ok());
  EXPECT_FALSE(ParsePiecesReply("pieces 2\nhull 4 4\n", 256).ok());
  const Result<ConvexPieceList> refused = ParsePiecesReply("error the mesh is open\n", 256);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.message(), "the mesh is open");
}

UrdfLoadOptions PiecesOptions() {
  UrdfLoadOptions options;
  const MeshProcessLimits limits = HelperLimits();
  options.mesh_hull_loader = [limits](const std::string& path, const Vec3& scale,
                                      const HullOptions& hull) {
    return CachedMeshHull(path, scale, hull, limits);
  };
  options.mesh_pieces_loader = [limits](const std::string& path, const Vec3& scale,
                                        const DecompositionOptions& decomposition,
                                        PiecesRule rule) {
    MeshPiecesRequest request;
    request.path = path;
    request.scale = scale;
    request.options = decomposition;
    request.rule = rule;
    return CachedMeshPieces(request, limits);
  };
  return options;
}

std::string MeshModel(const std::string& mesh, const std::string& mode,
                      const std::string& inertial = "") {
  std::string xml = "<robot name='m'><link name='base'>" + inertial +
                    "<collision name='c'><geometry><mesh filename='" + kDataDir + "/" + mesh +
                    "'/></geometry></collision></link>";
  if (!mode.empty()) {
    xml += "<gazebo reference='base'><mesh_collision>" + mode + "</mesh_collision></gazebo>";
  }
  return xml + "</robot>";
}

// The L-bracket (test/data/make_decomposition_meshes.py): 0.1 m deep, legs
// 0.3 m long and 0.05 m thick, volume 2.75e-3 m^3, its hull 5.875e-3 m^3
// (ratio 0.47: decomposed by default).
TEST(MeshPiecesTest, MovingConcaveMeshBecomesPiecesWithTheirMass) {
  const auto pieces = LoadUrdfString(MeshModel("l_bracket.stl", ""), PiecesOptions());
  ASSERT_TRUE(pieces.ok()) << pieces.message();
  EXPECT_GE(pieces->shapes.size(), 2u);
  // Mass from the pieces at 1000 kg/m^3: at least the L's, at most 1 % of
  // it more per piece.
  const double mass = pieces->mass_properties.mass;
  EXPECT_GE(mass, 2.75 * (1.0 - 1e-6));
  EXPECT_LE(mass, 2.75 * (1.0 + 0.01 * pieces->shapes.size()));

  const auto hull = LoadUrdfString(MeshModel("l_bracket.stl", "hull"), PiecesOptions());
  ASSERT_TRUE(hull.ok()) << hull.message();
  ASSERT_EQ(hull->shapes.size(), 1u);
  EXPECT_NEAR(hull->mass_properties.mass, 5.875, 1e-5);  // float STL coordinates

  const auto inertial = LoadUrdfString(
      MeshModel("l_bracket.stl", "decomposition",
                "<inertial><mass value='0.5'/><inertia ixx='0.01' iyy='0.01' izz='0.01' ixy='0' "
                "ixz='0' iyz='0'/></inertial>"),
      PiecesOptions());
  ASSERT_TRUE(inertial.ok()) << inertial.message();
  EXPECT_EQ(inertial->shapes.size(), pieces->shapes.size());
  EXPECT_EQ(inertial->mass_properties.mass, 0.5);
}

TEST(MeshPiecesTest, ConvexMovingMeshStaysOneHull) {
  const auto model = LoadUrdfString(MeshModel("chamfered_box_binary.stl", ""), PiecesOptions());
  ASSERT_TRUE(model.ok()) << model.message();
  EXPECT_EQ(model->shapes.size(), 1u);
}

TEST(MeshPiecesTest, UnknownModeIsRefusedByName) {
  const auto model = LoadUrdfString(MeshModel("mug.stl", "pieces"), PiecesOptions());
  ASSERT_FALSE(model.ok());
  EXPECT_NE(model.message().find("'triangles', 'hull', 'decomposition'"), std::string::npos)
      << model.message();
}

}  // namespace
}  // namespace rigid_body_sim::io
