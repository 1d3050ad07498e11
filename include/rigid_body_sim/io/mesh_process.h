// Mesh hulls built out of process: assimp and qhull run on untrusted files in
// a helper executable (rigid_body_sim_mesh_helper) started per mesh with
// posix_spawn, under limits on address space, CPU time and input size. An
// abort, an exhausted memory limit or a timeout in the helper is an error
// message here; whatever the importer leaks or crashes on stays in the
// child. The caller's process keeps a cache by path, scale, size and
// modification time, so a repeated mesh costs no process; convex pieces are
// also kept on disk, whose files are read as untrusted input (see
// MeshPiecesRequest::cache_directory). ROS-free.
#ifndef RIGID_BODY_SIM_IO_MESH_PROCESS_H_
#define RIGID_BODY_SIM_IO_MESH_PROCESS_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rigid_body_sim/io/convex_decomposition.h"
#include "rigid_body_sim/io/convex_hull.h"
#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

// Triangles of one static mesh by default (~max_mesh_triangles): 4 Mi, a
// reply of about 100 MB and a tree of about 1 GB at most.
inline constexpr std::uint64_t kDefaultMaxMeshTriangles = std::uint64_t{1} << 22;

// The limits of one mesh, in the order a request meets them: the file's
// size (before any process starts), then in the helper its triangles
// (a binary STL's before it is read), its memory and CPU time; the reply's
// size follows from the triangles and is never met first.
struct MeshProcessLimits {
  std::string helper_path;                                  // the helper executable
  std::uint64_t memory_bytes = std::uint64_t{1} << 30;      // RLIMIT_AS of the helper
  double cpu_seconds = 30.0;                                // RLIMIT_CPU; wall time 2x + 1 s
  std::uint64_t max_file_bytes = std::uint64_t{256} << 20;  // larger files are not opened
  // Most triangles of a static mesh (one that collides as its triangles),
  // in [1, CollisionMesh::kMaxTriangles].
  std::uint64_t max_triangles = kDefaultMaxMeshTriangles;
};

// The largest reply the node reads from the helper for `limits`: a
// triangles reply of max_triangles triangles with three vertices each of
// their own, and never less than kMaxHullReplyBytes. A reply past it is a
// helper gone wrong, not a mesh.
std::uint64_t MaxReplyBytes(const MeshProcessLimits& limits);
// Hull and pieces replies: 64 pieces of at most 2^16 vertices in text.
inline constexpr std::uint64_t kMaxHullReplyBytes = std::uint64_t{64} << 20;

// The hull of the mesh file at `path` (a local path, already resolved),
// scaled per axis, built by the helper. Fails naming the file on a file that
// is missing, not regular or too large (checked before any process starts),
// on the helper's refusal (its message), or on its death (the signal or the
// limit it hit).
physics::Result<physics::ConvexPolyhedron> LoadMeshHullOutOfProcess(
    const std::string& path, const physics::Vec3& scale, const HullOptions& hull,
    const MeshProcessLimits& limits);

// As above, through a process-wide cache keyed by path, scale, hull options,
// file size and modification time: a cached mesh starts no process. Failures
// are not cached. Thread-safe.
physics::Result<std::shared_ptr<const physics::ConvexPolyhedron>> CachedMeshHull(
    const std::string& path, const physics::Vec3& scale, const HullOptions& hull,
    const MeshProcessLimits& limits);

// The triangles of the mesh file at `path`, scaled per axis, read by the
// helper (for static meshes that collide as their triangles); fails as
// LoadMeshHullOutOfProcess does.
physics::Result<physics::TriangleMesh> LoadMeshTrianglesOutOfProcess(
    const std::string& path, const physics::Vec3& scale, const MeshProcessLimits& limits);

// As above, built into a CollisionMesh (its tree made here), through a
// process-wide cache keyed by path, scale, file size and modification time.
// Thread-safe.
physics::Result<std::shared_ptr<const physics::CollisionMesh>> CachedMeshTriangles(
    const std::string& path, const physics::Vec3& scale, const MeshProcessLimits& limits);

// A moving mesh's convex pieces (convex_decomposition.h), decomposed by
// the helper.
struct MeshPiecesRequest {
  std::string path;  // a local path, already resolved
  physics::Vec3 scale = physics::Vec3::Ones();
  DecompositionOptions options;
  PiecesRule rule = PiecesRule::kAuto;
  // Where results are kept on disk, one file (entry) per hash of the mesh
  // file's bytes and every setting above, so a mesh decomposed once (by any
  // run) costs no process again; empty: no disk cache. Anyone who can write
  // there may have left anything under an entry's name, so an entry is
  // untrusted input:
  // - it is used only if it is a regular file (a symbolic link is not
  //   followed, a FIFO or device is not read) of at most
  //   kMaxCacheEntryBytes, checked on the open descriptor;
  // - its text (FormatCacheEntry) must name format version
  //   kCacheFormatVersion, hold exactly these settings, and carry its
  //   body's byte count and 64-bit FNV-1a checksum, which must match; the
  //   body must parse as a pieces reply;
  // - anything else is a bad entry: ignored, reported by one warning naming
  //   its path and the reason (MeshCacheWarnings), rebuilt by the helper and
  //   written anew. An entry of the format before versions were named (its
  //   first line "key ...") is rebuilt without a warning.
  // The directory is made, mode 0700, when missing; a path that is not a
  // directory, or is a symbolic link, gets a warning and no disk cache. An
  // entry is written to a new file (mode 0600, never an existing one or
  // through a link) renamed over its name, so a reader never sees half an
  // entry; a reply whose entry would pass kMaxCacheEntryBytes is not kept.
  // Writing never fails the request: on any error the entry is not kept.
  std::string cache_directory;
};
using ConvexPieceList = std::vector<physics::ConvexPolyhedron>;

// The disk cache's warnings. This library cannot log: while a
// MeshCacheWarnings lives, the warnings that LoadMeshPiecesOutOfProcess
// (and so CachedMeshPieces) makes on the same thread are added to it (to
// the innermost, when they nest); with none alive they are dropped. The
// URDF loader keeps one around each mesh's pieces and passes what it
// collects on in LoadedModel::warnings, which the node logs. A bad entry is
// rewritten when it is read, and CachedMeshPieces answers from memory
// after that, so it is reported once.
class MeshCacheWarnings {
 public:
  MeshCacheWarnings();
  ~MeshCacheWarnings();
  MeshCacheWarnings(const MeshCacheWarnings&) = delete;
  MeshCacheWarnings& operator=(const MeshCacheWarnings&) = delete;

  const std::vector<std::string>& warnings() const { return warnings_; }
  // Adds `warning` to the calling thread's innermost MeshCacheWarnings, if
  // one is alive.
  static void Report(std::string warning);

 private:
  std::vector<std::string> warnings_;
  MeshCacheWarnings* outer_;  // the thread's collector before this one
};

// The pieces of the mesh at request.path: from the disk cache, else built
// by the helper (and then stored in the cache). Fails as
// LoadMeshHullOutOfProcess does.
physics::Result<ConvexPieceList> LoadMeshPiecesOutOfProcess(const MeshPiecesRequest& request,
                                                            const MeshProcessLimits& limits);

// As above, through a process-wide cache keyed by the request, the file's
// size and modification time. Thread-safe.
physics::Result<std::shared_ptr<const ConvexPieceList>> CachedMeshPieces(
    const MeshPiecesRequest& request, const MeshProcessLimits& limits);

// $ROS_HOME/rigid_body_sim/decomposition, else
// $HOME/.ros/rigid_body_sim/decomposition, else "" (no disk cache).
std::string DefaultDecompositionCacheDirectory();

// The helper's first argument that asks for triangles instead of a hull.
inline constexpr char kTrianglesFlag[] = "--triangles";
// A triangles reply is "triangles-binary V T\n" and then V vertices of three
// doubles and T triangles of three int32 indices, in the machine's byte
// order (the helper is the node's own build); the text form "triangles V
// T" with "v x y z" and "t i j k" lines is read too.
inline constexpr char kBinaryTrianglesWord[] = "triangles-binary";
inline constexpr std::size_t kBytesPerVertex = 3 * sizeof(double);
inline constexpr std::size_t kBytesPerTriangle = 3 * sizeof(std::int32_t);
// The helper's first argument that asks for convex pieces.
inline constexpr char kPiecesFlag[] = "--pieces";
// The pieces reply: "pieces N" and N hull replies.
std::string FormatPiecesReply(const ConvexPieceList& pieces);
// Parses a pieces reply of 1 to kMaxPieces hulls of at most `max_vertices`
// vertices each, or returns the helper's error.
physics::Result<ConvexPieceList> ParsePiecesReply(const std::string& reply, int max_vertices);
inline constexpr int kMaxPieces = 64;

// A disk-cache entry: the line "rigid_body_sim decomposition cache 2", the
// line "key " + `settings` (every setting the pieces depend on), the line
// "body <bytes> <checksum>" (the body's byte count in decimal and its
// 64-bit FNV-1a in 16 lowercase hexadecimal digits), then the body: the
// helper's pieces reply.
inline constexpr int kCacheFormatVersion = 2;
// The longest entry read or written: the pieces reply of kMaxPieces hulls
// of 1,024 vertices (HullOptions::max_vertices, 256 by default) at its
// longest text is 64 x (77 bytes per vertex line + at most 44 bytes per
// vertex of face lines, as a hull has at most 2V - 4 faces and 6V - 12
// face corners) = 7.9 MB, plus the header lines. Larger decompositions are
// not kept on disk.
inline constexpr std::size_t kMaxCacheEntryBytes = std::size_t{8} << 20;
std::string FormatCacheEntry(const std::string& settings, const std::string& reply);
// The pieces an entry's `text` holds for `settings` (hulls of at most
// `max_vertices` vertices each), or why the entry is bad: too long, another
// format or version, other settings, a body of another length or checksum,
// or a body that does not parse.
physics::Result<ConvexPieceList> ParseCacheEntry(const std::string& text,
                                                 const std::string& settings, int max_vertices);

// The helper's side, shared with it and with the fuzzer: the reply that
// carries a hull through the pipe, and its parsing. The text holds
// hexadecimal floats, so the parent gets the child's doubles exactly.
std::string FormatHullReply(const physics::ConvexPolyhedron& hull);
std::string FormatErrorReply(const std::string& message);
std::string FormatTrianglesReply(const physics::TriangleMesh& mesh);
// Parses a triangles reply (counts within CollisionMesh::kMaxTriangles,
// indices in range, finite coordinates), or returns the helper's error.
physics::Result<physics::TriangleMesh> ParseTrianglesReply(const std::string& reply);
// Parses a reply of at most `max_vertices` vertices into a polyhedron
// (MakeConvexPolyhedron checks it is closed and convex), or returns the
// helper's error message as the error.
physics::Result<physics::ConvexPolyhedron> ParseHullReply(const std::string& reply,
                                                          int max_vertices);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_MESH_PROCESS_H_
