#include "rigid_body_sim/io/mesh_process.h"

#include "io/mesh_process_internal.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <sstream>
#include <tuple>
#include <utility>

extern char** environ;

namespace rigid_body_sim::io {
namespace {

using physics::ConvexPolyhedron;
using physics::Result;
using physics::Status;
using physics::Vec3;

std::string Quoted(const std::string& text) { return "'" + text + "'"; }

// The text after "error " in a helper's refusal.
std::string RefusalText(const std::string& reply) {
  const std::size_t end = reply.find('\n');
  return reply.substr(6, end == std::string::npos ? end : end - 6);
}

}  // namespace

std::uint64_t MaxReplyBytes(const MeshProcessLimits& limits) {
  const std::uint64_t triangles =
      std::min<std::uint64_t>(limits.max_triangles, physics::CollisionMesh::kMaxTriangles);
  const std::uint64_t header = 64;
  return std::max(kMaxHullReplyBytes,
                  header + triangles * (3 * kBytesPerVertex + kBytesPerTriangle));
}

namespace internal {

std::string HexFloat(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%a", value);
  return buffer;
}

Result<struct stat> CheckFile(const std::string& path, std::uint64_t max_file_bytes) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) {
    return Result<struct stat>::Error("mesh file " + Quoted(path) +
                                      " cannot be read: " + std::strerror(errno));
  }
  if (!S_ISREG(info.st_mode)) {
    return Result<struct stat>::Error("mesh file " + Quoted(path) + " is not a regular file");
  }
  if (static_cast<std::uint64_t>(info.st_size) > max_file_bytes) {
    return Result<struct stat>::Error("mesh file " + Quoted(path) + " size " +
                                      std::to_string(info.st_size) + " bytes is above the limit " +
                                      std::to_string(max_file_bytes));
  }
  return info;
}

}  // namespace internal

namespace {

using internal::CheckFile;
using internal::HexFloat;

std::string DescribeLimits(const MeshProcessLimits& limits) {
  std::ostringstream out;
  out << "limits " << limits.memory_bytes << " bytes of memory, " << limits.cpu_seconds
      << " s of CPU";
  return out.str();
}

// Why the helper ended, from its wait status.
std::string DescribeDeath(int status, bool timed_out, const MeshProcessLimits& limits) {
  if (timed_out) {
    return "took longer than " + physics::FormatNumber(2.0 * limits.cpu_seconds + 1.0) +
           " s and was killed (" + DescribeLimits(limits) + ")";
  }
  if (WIFSIGNALED(status)) {
    const int signal = WTERMSIG(status);
    std::string what =
        "was killed by signal " + std::to_string(signal) + " (" + strsignal(signal) + ")";
    if (signal == SIGXCPU || signal == SIGKILL) what += ": it ran out of CPU time";
    if (signal == SIGABRT) what += ": the importer aborted";
    if (signal == SIGSEGV) what += ": the importer crashed";
    return what + " (" + DescribeLimits(limits) + ")";
  }
  return "exited with status " + std::to_string(WEXITSTATUS(status)) + " without a hull (" +
         DescribeLimits(limits) + ")";
}

// Runs the helper and returns its wait status and its standard output.
struct HelperRun {
  int status = 0;
  bool timed_out = false;
  bool oversized = false;  // the reply passed MaxReplyBytes
  std::string reply;
};

Result<HelperRun> RunHelper(const std::vector<std::string>& arguments,
                            const MeshProcessLimits& limits) {
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) {
    return Result<HelperRun>::Error(std::string("mesh helper: pipe: ") + std::strerror(errno));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 1);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  // The node's sockets and files are none of the helper's business.
  posix_spawn_file_actions_addclosefrom_np(&actions, 3);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t signals;
  sigemptyset(&signals);
  posix_spawnattr_setsigmask(&attributes, &signals);
  sigfillset(&signals);
  posix_spawnattr_setsigdefault(&attributes, &signals);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);

  std::vector<char*> argv;
  for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned =
      posix_spawn(&pid, limits.helper_path.c_str(), &actions, &attributes, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  ::close(pipe_fds[1]);
  if (spawned != 0) {
    ::close(pipe_fds[0]);
    return Result<HelperRun>::Error("mesh helper " + Quoted(limits.helper_path) +
                                    " cannot be started: " + std::strerror(spawned));
  }

  HelperRun run;
  const std::uint64_t max_reply_bytes = MaxReplyBytes(limits);
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration<double>(2.0 * limits.cpu_seconds + 1.0);
  char buffer[65536];
  for (;;) {
    // Rounded up: truncated, the last fraction of a millisecond counted as
    // none left and the helper was killed before its deadline.
    const auto left =
        std::chrono::ceil<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0 || run.reply.size() > max_reply_bytes) {
      ::kill(pid, SIGKILL);
      run.timed_out = left.count() <= 0;
      run.oversized = !run.timed_out;
      break;
    }
    pollfd readable{pipe_fds[0], POLLIN, 0};
    const int ready = ::poll(&readable, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) continue;
    const ssize_t count = ::read(pipe_fds[0], buffer, sizeof(buffer));
    if (count < 0 && errno == EINTR) continue;
    if (count <= 0) break;  // end of file: the helper is done
    run.reply.append(buffer, static_cast<std::size_t>(count));
  }
  ::close(pipe_fds[0]);
  while (::waitpid(pid, &run.status, 0) < 0 && errno == EINTR) {
  }
  return run;
}

}  // namespace

std::string FormatHullReply(const ConvexPolyhedron& hull) {
  std::string reply = "hull " + std::to_string(hull.vertices.size()) + " " +
                      std::to_string(hull.faces.size()) + "\n";
  for (const Vec3& vertex : hull.vertices) {
    reply += "v " + HexFloat(vertex.x()) + " " + HexFloat(vertex.y()) + " " + HexFloat(vertex.z()) +
             "\n";
  }
  for (int face = 0; face < static_cast<int>(hull.faces.size()); ++face) {
    const std::vector<int> loop = hull.FaceVertices(face);
    reply += "f " + std::to_string(loop.size());
    for (const int vertex : loop) reply += " " + std::to_string(vertex);
    reply += "\n";
  }
  return reply;
}

std::string FormatErrorReply(const std::string& message) {
  std::string line = message;
  for (char& c : line) {
    if (c == '\n') c = ' ';
  }
  return "error " + line + "\n";
}

std::string FormatTrianglesReply(const physics::TriangleMesh& mesh) {
  // Binary after the header line: a 2M-triangle terrain is some 50 MB this
  // way, and read by copying instead of parsing 3M hexadecimal floats.
  std::string reply = std::string(kBinaryTrianglesWord) + " " +
                      std::to_string(mesh.vertices.size()) + " " +
                      std::to_string(mesh.triangles.size()) + "\n";
  const std::size_t header = reply.size();
  reply.resize(header + kBytesPerVertex * mesh.vertices.size() +
               kBytesPerTriangle * mesh.triangles.size());
  char* out = reply.data() + header;
  for (const Vec3& vertex : mesh.vertices) {
    for (int k = 0; k < 3; ++k, out += sizeof(double)) std::memcpy(out, &vertex[k], sizeof(double));
  }
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    for (int k = 0; k < 3; ++k, out += sizeof(std::int32_t)) {
      const std::int32_t index = triangle[k];
      std::memcpy(out, &index, sizeof(index));
    }
  }
  return reply;
}

namespace {

// Reads one "v x y z" line of a reply into `vertex`; returns why it could
// not ("" when it could).
std::string ReadVertexLine(std::istream& in, Vec3* vertex) {
  std::string word;
  std::string coordinates[3];
  if (!(in >> word >> coordinates[0] >> coordinates[1] >> coordinates[2]) || word != "v") {
    return "a vertex line is malformed";
  }
  for (int k = 0; k < 3; ++k) {
    char* end = nullptr;
    (*vertex)[k] = std::strtod(coordinates[k].c_str(), &end);
    if (end == coordinates[k].c_str() || *end != '\0' || !std::isfinite((*vertex)[k])) {
      return "vertex coordinate " + Quoted(coordinates[k]) + " is not a finite number";
    }
  }
  return "";
}

}  // namespace

namespace {

// The binary body of a triangles reply from byte `start` on: V vertices of
// three little-endian doubles, then T triangles of three int32 indices;
// exactly that many bytes, finite coordinates, indices below V.
Result<physics::TriangleMesh> ParseBinaryTriangles(const std::string& reply, std::size_t start,
                                                   std::size_t vertex_count,
                                                   std::size_t triangle_count) {
  using Out = Result<physics::TriangleMesh>;
  const std::size_t expected = kBytesPerVertex * vertex_count + kBytesPerTriangle * triangle_count;
  if (reply.size() - start != expected) {
    return Out::Error("mesh helper reply: " + std::to_string(reply.size() - start) +
                      " bytes of vertices and triangles, expected " + std::to_string(expected));
  }
  const char* in = reply.data() + start;
  physics::TriangleMesh mesh;
  mesh.vertices.resize(vertex_count);
  for (Vec3& vertex : mesh.vertices) {
    for (int k = 0; k < 3; ++k, in += sizeof(double)) std::memcpy(&vertex[k], in, sizeof(double));
    if (!vertex.allFinite()) return Out::Error("mesh helper reply: a vertex is not finite");
  }
  mesh.triangles.resize(triangle_count);
  for (Eigen::Vector3i& triangle : mesh.triangles) {
    for (int k = 0; k < 3; ++k, in += sizeof(std::int32_t)) {
      std::int32_t index = -1;
      std::memcpy(&index, in, sizeof(index));
      if (index < 0 || static_cast<std::size_t>(index) >= vertex_count) {
        return Out::Error("mesh helper reply: a triangle has a vertex index outside [0, " +
                          std::to_string(vertex_count) + ")");
      }
      triangle[k] = index;
    }
  }
  return mesh;
}

}  // namespace

// Reads "triangles V T", V vertex lines of hexadecimal floats and T
// triangle lines of indices below V; counts within CollisionMesh's limit.
Result<physics::TriangleMesh> ParseTrianglesReply(const std::string& reply) {
  using Out = Result<physics::TriangleMesh>;
  const auto fail = [](const std::string& why) { return Out::Error("mesh helper reply: " + why); };
  if (reply.rfind("error ", 0) == 0) return Out::Error(RefusalText(reply));
  std::istringstream in(reply);
  std::string word;
  long vertex_count = 0;
  long triangle_count = 0;
  if (!(in >> word >> vertex_count >> triangle_count) ||
      (word != "triangles" && word != kBinaryTrianglesWord)) {
    return fail("no 'triangles <vertices> <triangles>' header");
  }
  const long most = static_cast<long>(physics::CollisionMesh::kMaxTriangles);
  if (vertex_count < 3 || vertex_count > 3 * most || triangle_count < 1 || triangle_count > most) {
    return fail(std::to_string(vertex_count) + " vertices and " + std::to_string(triangle_count) +
                " triangles are outside [3, " + std::to_string(3 * most) + "] and [1, " +
                std::to_string(most) + "]");
  }
  if (word == kBinaryTrianglesWord) {
    const std::size_t end_of_header = reply.find('\n');
    if (end_of_header == std::string::npos) return fail("the header line has no end");
    return ParseBinaryTriangles(reply, end_of_header + 1, static_cast<std::size_t>(vertex_count),
                                static_cast<std::size_t>(triangle_count));
  }
  physics::TriangleMesh mesh;
  mesh.vertices.resize(static_cast<std::size_t>(vertex_count));
  for (Vec3& vertex : mesh.vertices) {
    if (const std::string why = ReadVertexLine(in, &vertex); !why.empty()) return fail(why);
  }
  mesh.triangles.resize(static_cast<std::size_t>(triangle_count));
  for (Eigen::Vector3i& triangle : mesh.triangles) {
    if (!(in >> word) || word != "t") return fail("a triangle line is malformed");
    for (int k = 0; k < 3; ++k) {
      long value = -1;
      if (!(in >> value) || value < 0 || value >= vertex_count) {
        return fail("a triangle has a vertex index outside [0, " + std::to_string(vertex_count) +
                    ")");
      }
      triangle[k] = static_cast<int>(value);
    }
  }
  return mesh;
}

Result<ConvexPolyhedron> ParseHullReply(const std::string& reply, int max_vertices) {
  if (reply.rfind("error ", 0) == 0) return Result<ConvexPolyhedron>::Error(RefusalText(reply));
  std::istringstream in(reply);
  return internal::ParseHull(in, max_vertices);
}

std::string internal::RefusalOf(const std::string& reply) { return RefusalText(reply); }

Result<ConvexPolyhedron> internal::ParseHull(std::istream& in, int max_vertices) {
  const auto fail = [](const std::string& why) {
    return Result<ConvexPolyhedron>::Error("mesh helper reply: " + why);
  };
  std::string word;
  long vertex_count = 0;
  long face_count = 0;
  if (!(in >> word >> vertex_count >> face_count) || word != "hull") {
    return fail("no 'hull <vertices> <faces>' header");
  }
  // A convex polyhedron has F <= 2V - 4 faces.
  if (vertex_count < 4 || vertex_count > max_vertices || face_count < 4 ||
      face_count > 2 * vertex_count - 4) {
    return fail(std::to_string(vertex_count) + " vertices and " + std::to_string(face_count) +
                " faces are outside [4, " + std::to_string(max_vertices) + "] and [4, 2V - 4]");
  }
  std::vector<Vec3> vertices(static_cast<std::size_t>(vertex_count));
  for (Vec3& vertex : vertices) {
    if (const std::string why = ReadVertexLine(in, &vertex); !why.empty()) return fail(why);
  }
  std::vector<std::vector<int>> faces(static_cast<std::size_t>(face_count));
  for (std::vector<int>& face : faces) {
    long size = 0;
    if (!(in >> word >> size) || word != "f" || size < 3 || size > vertex_count) {
      return fail("a face line is malformed");
    }
    face.resize(static_cast<std::size_t>(size));
    for (int& index : face) {
      long value = -1;
      if (!(in >> value) || value < 0 || value >= vertex_count) {
        return fail("a face has a vertex index outside [0, " + std::to_string(vertex_count) + ")");
      }
      index = static_cast<int>(value);
    }
  }
  return physics::MakeConvexPolyhedron(vertices, faces);
}

// The helper's reply to `arguments` about the file at `path`, or why there
// is none: the file's own problem (checked before any process starts), the
// helper's refusal (with the limits, since an allocation that failed at the
// memory limit can look like a malformed file to the importer), its death,
// or a reply past MaxReplyBytes.
Result<std::string> internal::HelperReply(const std::vector<std::string>& arguments,
                                          const std::string& path,
                                          const MeshProcessLimits& limits) {
  if (Result<struct stat> file = CheckFile(path, limits.max_file_bytes); !file.ok()) {
    return file.status();
  }
  Result<HelperRun> run = RunHelper(arguments, limits);
  if (!run.ok()) return run.status();
  if (run->oversized) {
    return Result<std::string>::Error(
        "mesh " + Quoted(path) + ": the mesh helper's reply " + "passed " +
        std::to_string(MaxReplyBytes(limits)) + " bytes (what max_triangles " +
        std::to_string(limits.max_triangles) + " allows) and it was killed");
  }
  const bool exited = WIFEXITED(run->status);
  if (!run->timed_out && exited && run->reply.rfind("error ", 0) == 0) {
    return Result<std::string>::Error(RefusalText(run->reply) + " (in the mesh helper, " +
                                      DescribeLimits(limits) + ")");
  }
  if (run->timed_out || !exited || WEXITSTATUS(run->status) != 0) {
    return Result<std::string>::Error("mesh " + Quoted(path) + ": the mesh helper " +
                                      DescribeDeath(run->status, run->timed_out, limits));
  }
  return std::move(run->reply);
}

Status internal::CheckScale(const std::string& path, const Vec3& scale) {
  if (!scale.allFinite() || (scale.array() == 0.0).any()) {
    return Status::Error("mesh " + Quoted(path) +
                         ": scale must be finite and non-zero on every axis");
  }
  return Status::Ok();
}

using internal::CheckScale;
using internal::HelperReply;

Result<ConvexPolyhedron> LoadMeshHullOutOfProcess(const std::string& path, const Vec3& scale,
                                                  const HullOptions& hull,
                                                  const MeshProcessLimits& limits) {
  if (Status status = CheckScale(path, scale); !status.ok()) return status;
  const std::vector<std::string> arguments = {limits.helper_path,
                                              path,
                                              HexFloat(scale.x()),
                                              HexFloat(scale.y()),
                                              HexFloat(scale.z()),
                                              std::to_string(hull.max_vertices),
                                              HexFloat(hull.degenerate_tolerance),
                                              std::to_string(limits.memory_bytes),
                                              HexFloat(limits.cpu_seconds),
                                              std::to_string(limits.max_file_bytes)};
  Result<std::string> reply = HelperReply(arguments, path, limits);
  if (!reply.ok()) return reply.status();
  Result<ConvexPolyhedron> parsed = ParseHullReply(*reply, hull.max_vertices);
  if (!parsed.ok()) {
    return Result<ConvexPolyhedron>::Error("mesh " + Quoted(path) + ": " + parsed.message());
  }
  return parsed;
}

Result<physics::TriangleMesh> LoadMeshTrianglesOutOfProcess(const std::string& path,
                                                            const Vec3& scale,
                                                            const MeshProcessLimits& limits) {
  if (Status status = CheckScale(path, scale); !status.ok()) return status;
  const std::vector<std::string> arguments = {limits.helper_path,
                                              kTrianglesFlag,
                                              path,
                                              HexFloat(scale.x()),
                                              HexFloat(scale.y()),
                                              HexFloat(scale.z()),
                                              std::to_string(limits.max_triangles),
                                              std::to_string(limits.memory_bytes),
                                              HexFloat(limits.cpu_seconds),
                                              std::to_string(limits.max_file_bytes)};
  Result<std::string> reply = HelperReply(arguments, path, limits);
  if (!reply.ok()) return reply.status();
  Result<physics::TriangleMesh> parsed = ParseTrianglesReply(*reply);
  if (!parsed.ok()) {
    return Result<physics::TriangleMesh>::Error("mesh " + Quoted(path) + ": " + parsed.message());
  }
  return parsed;
}

Result<std::shared_ptr<const ConvexPolyhedron>> CachedMeshHull(const std::string& path,
                                                               const Vec3& scale,
                                                               const HullOptions& hull,
                                                               const MeshProcessLimits& limits) {
  using Out = Result<std::shared_ptr<const ConvexPolyhedron>>;
  const auto request = std::make_tuple(path, scale.x(), scale.y(), scale.z(), hull.max_vertices,
                                       hull.degenerate_tolerance);
  return internal::CachedByFile<ConvexPolyhedron>(path, request, limits, [&]() -> Out {
    Result<ConvexPolyhedron> built = LoadMeshHullOutOfProcess(path, scale, hull, limits);
    if (!built.ok()) return built.status();
    return std::make_shared<const ConvexPolyhedron>(std::move(built).value());
  });
}

Result<std::shared_ptr<const physics::CollisionMesh>> CachedMeshTriangles(
    const std::string& path, const Vec3& scale, const MeshProcessLimits& limits) {
  using Out = Result<std::shared_ptr<const physics::CollisionMesh>>;
  const auto request = std::make_tuple(path, scale.x(), scale.y(), scale.z());
  return internal::CachedByFile<physics::CollisionMesh>(path, request, limits, [&]() -> Out {
    Result<physics::TriangleMesh> triangles = LoadMeshTrianglesOutOfProcess(path, scale, limits);
    if (!triangles.ok()) return triangles.status();
    Out built = physics::CollisionMesh::Make(*triangles);
    if (!built.ok()) return Out::Error("mesh " + Quoted(path) + ": " + built.message());
    return built;
  });
}

}  // namespace rigid_body_sim::io
