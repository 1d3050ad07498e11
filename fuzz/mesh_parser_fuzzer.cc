// libFuzzer harness for what the mesh helper parses: the first byte picks a
// format (STL, OBJ, PLY, DAE), the rest is the file, imported by assimp and
// hulled by qhull as rigid_body_sim_mesh_helper does; then the same bytes
// as a helper reply, which the node parses. Neither may crash. (The helper
// runs under memory and CPU limits; here libFuzzer's -rss_limit_mb and
// -timeout stand in for them.)
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "rigid_body_sim/io/convex_hull.h"
#include "rigid_body_sim/io/mesh_loader.h"
#include "rigid_body_sim/io/mesh_process.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using rigid_body_sim::physics::Result;
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".stl", ".obj", ".ply", ".dae"};
  const std::string path =
      "/tmp/rbs_mesh_fuzz_" + std::to_string(getpid()) + kExtensions[data[0] % 4];
  if (FILE* file = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data + 1, 1, size - 1, file);
    std::fclose(file);
  }
  const auto as_is = [](const std::string& uri) -> Result<std::string> { return uri; };
  const Result<rigid_body_sim::physics::TriangleMesh> mesh =
      rigid_body_sim::io::LoadMesh(path, rigid_body_sim::physics::Vec3::Ones(), as_is);
  if (mesh.ok()) {
    const auto hull = rigid_body_sim::io::ComputeConvexHull(mesh->vertices);
    if (hull.ok()) {
      // What the helper sends must parse back to the same hull.
      const auto back =
          rigid_body_sim::io::ParseHullReply(rigid_body_sim::io::FormatHullReply(*hull), 1 << 20);
      if (!back.ok() || back->vertices != hull->vertices) std::abort();
    }
  }
  std::remove(path.c_str());
  const std::string reply(reinterpret_cast<const char*>(data), size);
  (void)rigid_body_sim::io::ParseHullReply(reply, 256);
  return 0;
}
