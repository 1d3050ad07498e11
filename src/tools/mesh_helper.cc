// rigid_body_sim_mesh_helper: imports one untrusted mesh file (assimp) and
// builds its convex hull (qhull) in a process of its own, so that an abort,
// a leak or a runaway allocation in the importer never reaches the node
// (io/mesh_process.h starts it). It limits itself before it touches the
// file, then writes the hull, or "error <why>", to its standard output.
//
// Usage: rigid_body_sim_mesh_helper PATH SX SY SZ MAX_VERTICES
//        DEGENERATE_TOLERANCE MEMORY_BYTES CPU_SECONDS MAX_FILE_BYTES
//    or: rigid_body_sim_mesh_helper --triangles PATH SX SY SZ MAX_TRIANGLES
//        MEMORY_BYTES CPU_SECONDS MAX_FILE_BYTES
// (the triangles themselves, for a static mesh that collides as them)
//    or: rigid_body_sim_mesh_helper --pieces PATH SX SY SZ auto|always
//        MAX_VERTICES DEGENERATE_TOLERANCE VOXELS MAX_PIECES MAX_CONCAVITY
//        BALANCE MERGE CONVEX_RATIO MEMORY_BYTES CPU_SECONDS MAX_FILE_BYTES
// (the convex pieces of a moving mesh, io/convex_decomposition.h).
#include <sys/resource.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <new>
#include <string>

#include "rigid_body_sim/io/convex_decomposition.h"
#include "rigid_body_sim/io/convex_hull.h"
#include "rigid_body_sim/io/mesh_loader.h"
#include "rigid_body_sim/io/mesh_process.h"

// GCC defines __SANITIZE_ADDRESS__; clang answers __has_feature.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RBS_HAS_ADDRESS_SANITIZER 1
#endif
#endif
#ifndef RBS_HAS_ADDRESS_SANITIZER
#define RBS_HAS_ADDRESS_SANITIZER 0
#endif

namespace {

using rigid_body_sim::physics::Result;

int Reply(const std::string& text, int status) {
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fflush(stdout);
  return status;
}

// Address space, CPU time (soft: SIGXCPU; hard one second later: SIGKILL)
// and no core files.
bool LimitSelf(rlim_t memory_bytes, double cpu_seconds) {
  const rlim_t cpu = static_cast<rlim_t>(cpu_seconds < 1.0 ? 1.0 : cpu_seconds);
  const rlimit memory{memory_bytes, memory_bytes};
  const rlimit cpu_limit{cpu, cpu + 1};
  const rlimit none{0, 0};
#if defined(__SANITIZE_ADDRESS__) || RBS_HAS_ADDRESS_SANITIZER
  // AddressSanitizer has reserved terabytes of address space for its
  // shadow before main: an address-space limit would fail every allocation.
  (void)memory;
#else
  if (setrlimit(RLIMIT_AS, &memory) != 0) return false;
#endif
  return setrlimit(RLIMIT_CPU, &cpu_limit) == 0 && setrlimit(RLIMIT_CORE, &none) == 0;
}

// What every mode takes: the file and its scale (the arguments after the
// mode's flag), and the limits (the last three arguments).
struct Request {
  std::string path;
  rigid_body_sim::physics::Vec3 scale;
  unsigned long long memory_bytes = 0;
  double cpu_seconds = 0.0;
  unsigned long long max_file_bytes = 0;
};

Request ReadRequest(int argc, char** argv, int first) {
  Request request;
  request.path = argv[first];
  request.scale = rigid_body_sim::physics::Vec3(std::strtod(argv[first + 1], nullptr),
                                                std::strtod(argv[first + 2], nullptr),
                                                std::strtod(argv[first + 3], nullptr));
  request.memory_bytes = std::strtoull(argv[argc - 3], nullptr, 10);
  request.cpu_seconds = std::strtod(argv[argc - 2], nullptr);
  request.max_file_bytes = std::strtoull(argv[argc - 1], nullptr, 10);
  return request;
}

// Limits the process, loads the file and replies with what `build` makes of
// its triangles; an importer's exception, out of memory included, becomes
// an error reply.
int Serve(
    const Request& request,
    const std::function<Result<std::string>(const rigid_body_sim::physics::TriangleMesh&)>& build) {
  using rigid_body_sim::io::FormatErrorReply;
  if (!LimitSelf(static_cast<rlim_t>(request.memory_bytes), request.cpu_seconds)) {
    return Reply(FormatErrorReply("mesh helper: setrlimit failed"), 2);
  }
  const std::string& path = request.path;
  try {
    // The path is already resolved; take it as it is.
    const auto as_is = [](const std::string& uri) -> Result<std::string> { return uri; };
    const Result<rigid_body_sim::physics::TriangleMesh> mesh =
        rigid_body_sim::io::LoadMesh(path, request.scale, as_is, request.max_file_bytes);
    if (!mesh.ok()) return Reply(FormatErrorReply(mesh.message()), 1);
    const Result<std::string> reply = build(*mesh);
    if (!reply.ok()) return Reply(FormatErrorReply("mesh '" + path + "': " + reply.message()), 1);
    return Reply(*reply, 0);
  } catch (const std::bad_alloc&) {
    return Reply(FormatErrorReply("mesh '" + path + "': out of memory in the mesh helper (limit " +
                                  std::to_string(request.memory_bytes) + " bytes)"),
                 1);
  } catch (const std::exception& error) {
    return Reply(FormatErrorReply("mesh '" + path + "': " + error.what()), 1);
  }
}

// `path` is "mesh '<file>' " where the reply does not name the file itself.
std::string TooManyTriangles(const std::string& path, unsigned long long count,
                             unsigned long long most) {
  return path + "has " + std::to_string(count) + " triangles, more than the limit of " +
         std::to_string(most) + " for a static mesh (~max_mesh_triangles)";
}

// A binary STL's triangle count, from its header, when the file is one: 80
// bytes, a uint32 count n, and 50 bytes per triangle, 84 + 50 n in all.
// Read before the importer runs, so an oversized terrain is refused at once.
bool BinaryStlTriangles(const std::string& path, unsigned long long* count) {
  const std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos) return false;
  std::string extension = path.substr(dot);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension != ".stl") return false;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return false;
  unsigned char header[84];
  const bool read = std::fread(header, 1, sizeof(header), file) == sizeof(header);
  const bool sized = std::fseek(file, 0, SEEK_END) == 0;
  const long size = sized ? std::ftell(file) : -1;
  std::fclose(file);
  if (!read || size < 84) return false;
  const unsigned long long n = static_cast<unsigned long long>(header[80]) |
                               static_cast<unsigned long long>(header[81]) << 8 |
                               static_cast<unsigned long long>(header[82]) << 16 |
                               static_cast<unsigned long long>(header[83]) << 24;
  if (84 + 50 * n != static_cast<unsigned long long>(size)) return false;  // ASCII
  *count = n;
  return true;
}

// --triangles: the scaled triangles of the file, at most MAX_TRIANGLES.
int ReplyTriangles(int argc, char** argv) {
  using rigid_body_sim::io::FormatErrorReply;
  if (argc != 10) return Reply(FormatErrorReply("mesh helper: expected 9 arguments"), 2);
  const Request request = ReadRequest(argc, argv, 2);
  const unsigned long long most = std::strtoull(argv[6], nullptr, 10);
  if (unsigned long long count = 0; BinaryStlTriangles(request.path, &count) && count > most) {
    return Reply(FormatErrorReply(TooManyTriangles("mesh '" + request.path + "' ", count, most)),
                 1);
  }
  return Serve(request, [&](const rigid_body_sim::physics::TriangleMesh& mesh) {
    if (mesh.triangles.size() > most) {
      return Result<std::string>::Error(TooManyTriangles("", mesh.triangles.size(), most));
    }
    return Result<std::string>(rigid_body_sim::io::FormatTrianglesReply(mesh));
  });
}

// --pieces: the mesh's convex pieces.
int ReplyPieces(int argc, char** argv) {
  using rigid_body_sim::io::FormatErrorReply;
  if (argc != 18) return Reply(FormatErrorReply("mesh helper: expected 17 arguments"), 2);
  const std::string rule_name = argv[6];
  if (rule_name != "auto" && rule_name != "always") {
    return Reply(FormatErrorReply("mesh helper: rule '" + rule_name + "' is not auto or always"),
                 2);
  }
  rigid_body_sim::io::DecompositionOptions options;
  options.hull.max_vertices = std::atoi(argv[7]);
  options.hull.degenerate_tolerance = std::strtod(argv[8], nullptr);
  options.voxel_count = std::atoi(argv[9]);
  options.max_pieces = std::atoi(argv[10]);
  options.max_concavity = std::strtod(argv[11], nullptr);
  options.balance_weight = std::strtod(argv[12], nullptr);
  options.merge_volume = std::strtod(argv[13], nullptr);
  options.convex_ratio = std::strtod(argv[14], nullptr);
  const auto rule = rule_name == "auto" ? rigid_body_sim::io::PiecesRule::kAuto
                                        : rigid_body_sim::io::PiecesRule::kAlways;
  return Serve(ReadRequest(argc, argv, 2),
               [&](const rigid_body_sim::physics::TriangleMesh& mesh) -> Result<std::string> {
                 const auto pieces = rigid_body_sim::io::ConvexPieces(mesh, options, rule);
                 if (!pieces.ok()) return pieces.status();
                 return rigid_body_sim::io::FormatPiecesReply(*pieces);
               });
}

}  // namespace

int main(int argc, char** argv) {
  using rigid_body_sim::io::FormatErrorReply;
  if (argc > 1 && std::string(argv[1]) == rigid_body_sim::io::kTrianglesFlag) {
    return ReplyTriangles(argc, argv);
  }
  if (argc > 1 && std::string(argv[1]) == rigid_body_sim::io::kPiecesFlag) {
    return ReplyPieces(argc, argv);
  }
  if (argc != 10) return Reply(FormatErrorReply("mesh helper: expected 9 arguments"), 2);
  rigid_body_sim::io::HullOptions hull;
  hull.max_vertices = std::atoi(argv[5]);
  hull.degenerate_tolerance = std::strtod(argv[6], nullptr);
  return Serve(ReadRequest(argc, argv, 1),
               [&](const rigid_body_sim::physics::TriangleMesh& mesh) -> Result<std::string> {
                 const auto built = rigid_body_sim::io::ComputeConvexHull(mesh.vertices, hull);
                 if (!built.ok()) return built.status();
                 return rigid_body_sim::io::FormatHullReply(*built);
               });
}
