// libFuzzer harness for the mesh helper and its protocol. The bytes are, in
// turn: a helper reply, which the node parses as a hull (ParseHullReply) and
// as a convex decomposition's pieces (ParsePiecesReply); a point set, hulled
// by qhull as the helper does, whose hull reply, and pieces reply with the
// hull as two pieces, must parse back to the same hulls; and a mesh file
// (first byte: STL, OBJ, PLY or DAE) handed to the real helper process,
// whose answer, death or timeout must come back as a result. Assimp itself
// runs only in the helper: in process it loops forever on some headers
// (test/data/hang_header.ply, found here), which is what the helper's CPU
// limit is for.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "rigid_body_sim/io/convex_hull.h"
#include "rigid_body_sim/io/mesh_process.h"

namespace {

using rigid_body_sim::physics::Vec3;

void CheckHullRoundTrip(const std::uint8_t* data, std::size_t size) {
  std::vector<Vec3> points;
  for (std::size_t i = 0; i + 3 * sizeof(float) <= size && points.size() < 64;
       i += 3 * sizeof(float)) {
    float xyz[3];
    std::memcpy(xyz, data + i, sizeof(xyz));
    points.emplace_back(xyz[0], xyz[1], xyz[2]);
  }
  const auto hull = rigid_body_sim::io::ComputeConvexHull(points);
  if (!hull.ok()) return;
  const auto back =
      rigid_body_sim::io::ParseHullReply(rigid_body_sim::io::FormatHullReply(*hull), 1 << 20);
  if (!back.ok() || back->vertices != hull->vertices) std::abort();
  const rigid_body_sim::io::ConvexPieceList pieces{*hull, *hull};
  const auto parsed =
      rigid_body_sim::io::ParsePiecesReply(rigid_body_sim::io::FormatPiecesReply(pieces), 1 << 20);
  if (!parsed.ok() || parsed->size() != 2) std::abort();
  for (const auto& piece : *parsed) {
    if (piece.vertices != hull->vertices) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string reply(reinterpret_cast<const char*>(data), size);
  (void)rigid_body_sim::io::ParseHullReply(reply, 256);
  (void)rigid_body_sim::io::ParsePiecesReply(reply, 256);
  CheckHullRoundTrip(data, size);
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".stl", ".obj", ".ply", ".dae"};
  const std::string path =
      "/tmp/rbs_mesh_fuzz_" + std::to_string(getpid()) + kExtensions[data[0] % 4];
  if (FILE* file = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data + 1, 1, size - 1, file);
    std::fclose(file);
  }
  rigid_body_sim::io::MeshProcessLimits limits;
  limits.helper_path = RBS_MESH_HELPER;
  limits.cpu_seconds = 1.0;
  const auto hull = rigid_body_sim::io::LoadMeshHullOutOfProcess(
      path, Vec3::Ones(), rigid_body_sim::io::HullOptions(), limits);
  if (!hull.ok() && hull.message().empty()) std::abort();  // a failure must say why
  std::remove(path.c_str());
  return 0;
}
