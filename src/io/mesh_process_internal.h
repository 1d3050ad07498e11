// What mesh_process.cc shares with mesh_pieces.cc: running the helper,
// checks made before it runs, the hull reply's parser, and the in-memory
// cache every kind of helper result goes through.
#ifndef RIGID_BODY_SIM_IO_MESH_PROCESS_INTERNAL_H_
#define RIGID_BODY_SIM_IO_MESH_PROCESS_INTERNAL_H_

#include <sys/stat.h>

#include <cstdint>
#include <istream>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "rigid_body_sim/io/mesh_process.h"

namespace rigid_body_sim::io::internal {

// Entries at most per cache; past it the cache starts afresh.
inline constexpr std::size_t kMaxCachedEntries = 1024;

// A double as a C99 hexadecimal float: the helper's arguments and replies
// carry doubles exactly.
std::string HexFloat(double value);

// The file is regular and small enough; checked before anything opens it.
physics::Result<struct stat> CheckFile(const std::string& path, std::uint64_t max_file_bytes);

// Every scale factor finite and non-zero, or a message naming the mesh.
physics::Status CheckScale(const std::string& path, const physics::Vec3& scale);

// The helper's reply to `arguments` about the file at `path`, or why there
// is none: the file's own problem (checked before any process starts), the
// helper's refusal (with the limits), its death or timeout, or an oversized
// reply.
physics::Result<std::string> HelperReply(const std::vector<std::string>& arguments,
                                         const std::string& path, const MeshProcessLimits& limits);

// The text after "error " of a reply that starts with it.
std::string RefusalOf(const std::string& reply);

// Reads one "hull V F" section (at most `max_vertices` vertices) from `in`.
physics::Result<physics::ConvexPolyhedron> ParseHull(std::istream& in, int max_vertices);

// A process-wide cache of what `build` makes from the file at `path`, keyed
// by `request` (what was asked of the file) and the file's size and
// modification time, so an edited file is built again. Failures are not
// cached. Thread-safe; one cache per Value and Request type.
template <typename Value, typename Request, typename Build>
physics::Result<std::shared_ptr<const Value>> CachedByFile(const std::string& path,
                                                           const Request& request,
                                                           const MeshProcessLimits& limits,
                                                           const Build& build) {
  using Key = std::pair<Request, std::tuple<std::int64_t, std::int64_t, std::int64_t>>;
  static std::mutex mutex;
  static std::map<Key, std::shared_ptr<const Value>> cache;
  physics::Result<struct stat> file = CheckFile(path, limits.max_file_bytes);
  if (!file.ok()) return file.status();
  const Key key{
      request,
      {static_cast<std::int64_t>(file->st_size), static_cast<std::int64_t>(file->st_mtim.tv_sec),
       static_cast<std::int64_t>(file->st_mtim.tv_nsec)}};
  {
    std::lock_guard<std::mutex> lock(mutex);
    const auto found = cache.find(key);
    if (found != cache.end()) return found->second;
  }
  physics::Result<std::shared_ptr<const Value>> built = build();
  if (!built.ok()) return built;
  std::lock_guard<std::mutex> lock(mutex);
  if (cache.size() >= kMaxCachedEntries) cache.clear();
  cache.emplace(key, *built);
  return built;
}

}  // namespace rigid_body_sim::io::internal

#endif  // RIGID_BODY_SIM_IO_MESH_PROCESS_INTERNAL_H_
