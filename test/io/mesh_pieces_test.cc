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
  const std::filesystem::path directory =
      std::filesystem::temp_directory_path() /
      ("rbs_mesh_pieces_test_" + std::to_string(getpid())) / name;
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

}  // namespace
}  // namespace rigid_body_sim::io
