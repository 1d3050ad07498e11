// Mesh hulls out of process: the helper's hull is the in-process hull to
// the bit; its death by abort, timeout or memory limit is an error message;
// bad files never start it; the cache starts no process for a mesh it holds.
#include "rigid_body_sim/io/mesh_process.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "rigid_body_sim/io/convex_hull.h"
#include "rigid_body_sim/io/mesh_loader.h"

namespace rigid_body_sim::io {
namespace {

using physics::ConvexPolyhedron;
using physics::Result;
using physics::Vec3;

const std::string kDataDir = RBS_TEST_DATA_DIR;

MeshProcessLimits HelperLimits() {
  MeshProcessLimits limits;
  limits.helper_path = RBS_MESH_HELPER;
  return limits;
}

// An executable shell script in a fresh temporary directory.
std::string Script(const std::string& name, const std::string& body) {
  const std::filesystem::path directory = std::filesystem::temp_directory_path() /
                                          ("rbs_mesh_process_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(directory);
  const std::string path = (directory / name).string();
  std::ofstream(path) << "#!/bin/sh\n" << body << "\n";
  std::filesystem::permissions(path, std::filesystem::perms::owner_all);
  return path;
}

TEST(MeshProcessTest, HelperHullIsTheInProcessHullExactly) {
  const std::string path = kDataDir + "/chamfered_box_binary.stl";
  const Vec3 scale(2.0, 1.0, 0.5);
  const Result<ConvexPolyhedron> remote =
      LoadMeshHullOutOfProcess(path, scale, HullOptions(), HelperLimits());
  ASSERT_TRUE(remote.ok()) << remote.message();
  const Result<physics::TriangleMesh> mesh = LoadMesh(path, scale);
  ASSERT_TRUE(mesh.ok());
  const Result<ConvexPolyhedron> local = ComputeConvexHull(mesh->vertices);
  ASSERT_TRUE(local.ok());
  ASSERT_EQ(remote->vertices.size(), local->vertices.size());
  for (std::size_t i = 0; i < local->vertices.size(); ++i) {
    EXPECT_EQ(remote->vertices[i], local->vertices[i]) << "vertex " << i;
  }
  EXPECT_EQ(remote->faces.size(), local->faces.size());
  EXPECT_EQ(remote->EdgeCount(), local->EdgeCount());
}

TEST(MeshProcessTest, BadFilesAreRefusedBeforeAnyProcess) {
  MeshProcessLimits limits = HelperLimits();
  limits.helper_path = "/nonexistent/helper";  // would fail if it were started
  const Result<ConvexPolyhedron> zero =
      LoadMeshHullOutOfProcess("/dev/zero", Vec3::Ones(), HullOptions(), limits);
  ASSERT_FALSE(zero.ok());
  EXPECT_EQ(zero.message(), "mesh file '/dev/zero' is not a regular file");
  limits.max_file_bytes = 10;
  const Result<ConvexPolyhedron> big = LoadMeshHullOutOfProcess(
      kDataDir + "/chamfered_box.obj", Vec3::Ones(), HullOptions(), limits);
  ASSERT_FALSE(big.ok());
  EXPECT_NE(big.message().find("is above the limit 10"), std::string::npos) << big.message();
}

TEST(MeshProcessTest, HelperRefusalComesBackAsItsMessage) {
  const Result<ConvexPolyhedron> empty = LoadMeshHullOutOfProcess(
      kDataDir + "/empty.stl", Vec3::Ones(), HullOptions(), HelperLimits());
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.message().find("empty.stl"), std::string::npos) << empty.message();
}

TEST(MeshProcessTest, AbortIsReportedNotPropagated) {
  MeshProcessLimits limits = HelperLimits();
  limits.helper_path = Script("abort.sh", "kill -ABRT $$");
  const Result<ConvexPolyhedron> hull = LoadMeshHullOutOfProcess(
      kDataDir + "/chamfered_box.obj", Vec3::Ones(), HullOptions(), limits);
  ASSERT_FALSE(hull.ok());
  EXPECT_NE(hull.message().find("killed by signal 6"), std::string::npos) << hull.message();
  EXPECT_NE(hull.message().find("the importer aborted"), std::string::npos) << hull.message();
}

// CPU limit 0.5 s: the wall-time deadline is 2 x 0.5 + 1 = 2 s, after which
// a helper stuck in a sleep is killed.
TEST(MeshProcessTest, StuckHelperIsKilledAtTheDeadline) {
  MeshProcessLimits limits = HelperLimits();
  limits.helper_path = Script("stuck.sh", "exec sleep 30");
  limits.cpu_seconds = 0.5;
  const auto start = std::chrono::steady_clock::now();
  const Result<ConvexPolyhedron> hull = LoadMeshHullOutOfProcess(
      kDataDir + "/chamfered_box.obj", Vec3::Ones(), HullOptions(), limits);
  const double waited =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(hull.ok());
  EXPECT_NE(hull.message().find("took longer than 2 s and was killed"), std::string::npos)
      << hull.message();
  EXPECT_GE(waited, 2.0);
  EXPECT_LT(waited, 5.0);
}

// An ASCII PLY whose header the fuzzer corrupted (mesh_parser_fuzzer found
// it in its first minute): assimp's PLY reader loops on it forever. The
// helper's CPU limit of 1 s ends it; the caller gets a message.
TEST(MeshProcessTest, ImporterLoopingForeverIsStoppedByTheCpuLimit) {
  MeshProcessLimits limits = HelperLimits();
  limits.cpu_seconds = 1.0;
  const auto start = std::chrono::steady_clock::now();
  const Result<ConvexPolyhedron> hull =
      LoadMeshHullOutOfProcess(kDataDir + "/hang_header.ply", Vec3::Ones(), HullOptions(), limits);
  const double waited =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(hull.ok());
  EXPECT_NE(hull.message().find("ran out of CPU time"), std::string::npos) << hull.message();
  EXPECT_LT(waited, 3.5);  // the wall-time deadline is 2 x 1 + 1 s
}

// 16 MiB of address space is less than the helper has mapped at start, so
// the importer's allocations fail: an error naming the limit (assimp may
// take its failed allocation for a malformed file), not a dead caller.
TEST(MeshProcessTest, MemoryLimitIsReported) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "the helper sets no address-space limit under AddressSanitizer";
#endif
  MeshProcessLimits limits = HelperLimits();
  limits.memory_bytes = std::uint64_t{16} << 20;
  const Result<ConvexPolyhedron> hull = LoadMeshHullOutOfProcess(
      kDataDir + "/chamfered_box_zup.dae", Vec3::Ones(), HullOptions(), limits);
  ASSERT_FALSE(hull.ok());
  EXPECT_NE(hull.message().find("16777216 bytes of memory"), std::string::npos) << hull.message();
  // With the default 1 GiB the same file loads.
  EXPECT_TRUE(LoadMeshHullOutOfProcess(kDataDir + "/chamfered_box_zup.dae", Vec3::Ones(),
                                       HullOptions(), HelperLimits())
                  .ok());
}

TEST(MeshProcessTest, CacheStartsNoProcessForAKnownFileAndSeesChanges) {
  const std::filesystem::path copy =
      std::filesystem::temp_directory_path() / ("rbs_cache_" + std::to_string(getpid()) + ".obj");
  std::filesystem::copy_file(kDataDir + "/chamfered_box.obj", copy,
                             std::filesystem::copy_options::overwrite_existing);
  MeshProcessLimits limits = HelperLimits();
  const auto first = CachedMeshHull(copy.string(), Vec3::Ones(), HullOptions(), limits);
  ASSERT_TRUE(first.ok()) << first.message();
  // A helper that cannot start: only the cache can answer now.
  limits.helper_path = "/nonexistent/helper";
  const auto start = std::chrono::steady_clock::now();
  const auto again = CachedMeshHull(copy.string(), Vec3::Ones(), HullOptions(), limits);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(again.ok()) << again.message();
  EXPECT_EQ(again->get(), first->get());
  EXPECT_LT(ms, 5.0);
  // Another modification time is another file: the helper must run again.
  std::filesystem::last_write_time(
      copy, std::filesystem::last_write_time(copy) + std::chrono::seconds(10));
  const auto changed = CachedMeshHull(copy.string(), Vec3::Ones(), HullOptions(), limits);
  ASSERT_FALSE(changed.ok());
  EXPECT_NE(changed.message().find("cannot be started"), std::string::npos) << changed.message();
  std::filesystem::remove(copy);
}

TEST(MeshProcessTest, MalformedRepliesAreRefused) {
  EXPECT_EQ(ParseHullReply("error boom\n", 256).message(), "boom");
  EXPECT_FALSE(ParseHullReply("", 256).ok());
  EXPECT_FALSE(ParseHullReply("hull 3 4\n", 256).ok());
  EXPECT_FALSE(ParseHullReply("hull 300 4\n", 256).ok());
  // A tetrahedron whose last face names vertex 7 of 4.
  const std::string tetrahedron =
      "hull 4 4\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 3 0 2 1\nf 3 0 1 3\nf 3 1 2 3\n";
  EXPECT_FALSE(ParseHullReply(tetrahedron + "f 3 0 3 7\n", 256).ok());
  const Result<ConvexPolyhedron> good = ParseHullReply(tetrahedron + "f 3 0 3 2\n", 256);
  ASSERT_TRUE(good.ok()) << good.message();
  EXPECT_EQ(good->vertices.size(), 4u);
  EXPECT_EQ(good->faces.size(), 4u);
  EXPECT_EQ(ParseHullReply(FormatHullReply(*good), 256)->vertices, good->vertices);
}

}  // namespace
}  // namespace rigid_body_sim::io
