// Convex pieces of moving meshes from the helper process, with a disk cache
// keyed by the file's bytes and the decomposition settings (mesh_process.h).
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "io/mesh_process_internal.h"
#include "rigid_body_sim/io/mesh_process.h"

namespace rigid_body_sim::io {
namespace {

using internal::HexFloat;
using physics::ConvexPolyhedron;
using physics::Result;
using physics::Status;

std::string Quoted(const std::string& text) { return "'" + text + "'"; }

const char* RuleName(PiecesRule rule) { return rule == PiecesRule::kAuto ? "auto" : "always"; }

// Every setting the pieces depend on, in one line; the disk cache's key
// holds it whole, so two settings never share a cache file.
std::string SettingsLine(const MeshPiecesRequest& request) {
  const DecompositionOptions& o = request.options;
  return "v1 scale " + HexFloat(request.scale.x()) + " " + HexFloat(request.scale.y()) + " " +
         HexFloat(request.scale.z()) + " rule " + RuleName(request.rule) + " voxels " +
         std::to_string(o.voxel_count) + " pieces " + std::to_string(o.max_pieces) + " concavity " +
         HexFloat(o.max_concavity) + " balance " + HexFloat(o.balance_weight) + " merge " +
         HexFloat(o.merge_volume) + " ratio " + HexFloat(o.convex_ratio) + " hull " +
         std::to_string(o.hull.max_vertices) + " " + HexFloat(o.hull.degenerate_tolerance);
}

// 64-bit FNV-1a (Fowler, Noll, Vo), twice with different offset bases, and
// the byte count: a 128-bit name for the file's content plus the settings.
std::string CacheName(const std::string& content, const std::string& settings) {
  std::uint64_t first = 0xcbf29ce484222325ULL;
  std::uint64_t second = 0x84222325cbf29ce4ULL;
  constexpr std::uint64_t kPrime = 0x100000001b3ULL;
  for (const unsigned char byte : content + '\n' + settings) {
    first = (first ^ byte) * kPrime;
    second = (second ^ static_cast<unsigned char>(byte + 0x5b)) * kPrime;
  }
  char name[64];
  std::snprintf(name, sizeof(name), "%016llx%016llx-%zu.pieces",
                static_cast<unsigned long long>(first), static_cast<unsigned long long>(second),
                content.size());
  return name;
}

Result<std::string> ReadWhole(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return Result<std::string>::Error("cannot be read");
  std::ostringstream contents;
  contents << file.rdbuf();
  return contents.str();
}

// The cached reply for `settings`, if the file holds one; a file of other
// settings (a hash collision) or a malformed one is a miss.
Result<ConvexPieceList> ReadCache(const std::string& cache_path, const std::string& settings,
                                  int max_vertices) {
  Result<std::string> text = ReadWhole(cache_path);
  if (!text.ok()) return text.status();
  const std::string header = "key " + settings + "\n";
  if (text->compare(0, header.size(), header) != 0) {
    return Result<ConvexPieceList>::Error("holds other settings");
  }
  return ParsePiecesReply(text->substr(header.size()), max_vertices);
}

// Written to a file of its own, then renamed over the name, so a reader
// never sees half a file and concurrent writers do not mix.
void WriteCache(const std::string& directory, const std::string& cache_path,
                const std::string& settings, const std::string& reply) {
  static std::atomic<int> counter{0};
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) return;
  const std::string temporary = cache_path + ".tmp." + std::to_string(::getpid()) + "." +
                                std::to_string(counter.fetch_add(1));
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file) return;
    file << "key " << settings << "\n" << reply;
    if (!file.flush()) {
      std::filesystem::remove(temporary, error);
      return;
    }
  }
  std::filesystem::rename(temporary, cache_path, error);
  if (error) std::filesystem::remove(temporary, error);
}

std::vector<std::string> HelperArguments(const MeshPiecesRequest& request,
                                         const MeshProcessLimits& limits) {
  const DecompositionOptions& o = request.options;
  return {limits.helper_path,
          kPiecesFlag,
          request.path,
          HexFloat(request.scale.x()),
          HexFloat(request.scale.y()),
          HexFloat(request.scale.z()),
          RuleName(request.rule),
          std::to_string(o.hull.max_vertices),
          HexFloat(o.hull.degenerate_tolerance),
          std::to_string(o.voxel_count),
          std::to_string(o.max_pieces),
          HexFloat(o.max_concavity),
          HexFloat(o.balance_weight),
          HexFloat(o.merge_volume),
          HexFloat(o.convex_ratio),
          std::to_string(limits.memory_bytes),
          HexFloat(limits.cpu_seconds),
          std::to_string(limits.max_file_bytes)};
}

}  // namespace

std::string FormatPiecesReply(const ConvexPieceList& pieces) {
  std::string reply = "pieces " + std::to_string(pieces.size()) + "\n";
  for (const ConvexPolyhedron& piece : pieces) reply += FormatHullReply(piece);
  return reply;
}

Result<ConvexPieceList> ParsePiecesReply(const std::string& reply, int max_vertices) {
  using Out = Result<ConvexPieceList>;
  if (reply.rfind("error ", 0) == 0) return Out::Error(internal::RefusalOf(reply));
  std::istringstream in(reply);
  std::string word;
  long count = 0;
  if (!(in >> word >> count) || word != "pieces") {
    return Out::Error("mesh helper reply: no 'pieces <count>' header");
  }
  if (count < 1 || count > kMaxPieces) {
    return Out::Error("mesh helper reply: " + std::to_string(count) + " pieces are outside [1, " +
                      std::to_string(kMaxPieces) + "]");
  }
  ConvexPieceList pieces;
  for (long i = 0; i < count; ++i) {
    Result<ConvexPolyhedron> piece = internal::ParseHull(in, max_vertices);
    if (!piece.ok()) return piece.status();
    pieces.push_back(std::move(piece).value());
  }
  return pieces;
}

std::string DefaultDecompositionCacheDirectory() {
  const char* ros_home = std::getenv("ROS_HOME");
  if (ros_home != nullptr && ros_home[0] != '\0') {
    return std::string(ros_home) + "/rigid_body_sim/decomposition";
  }
  const char* home = std::getenv("HOME");
  if (home != nullptr && home[0] != '\0') {
    return std::string(home) + "/.ros/rigid_body_sim/decomposition";
  }
  return "";
}

Result<ConvexPieceList> LoadMeshPiecesOutOfProcess(const MeshPiecesRequest& request,
                                                   const MeshProcessLimits& limits) {
  using Out = Result<ConvexPieceList>;
  if (Status status = internal::CheckScale(request.path, request.scale); !status.ok()) {
    return status;
  }
  if (Status status = CheckDecompositionOptions(request.options); !status.ok()) return status;
  const std::string settings = SettingsLine(request);
  std::string cache_path;
  if (!request.cache_directory.empty()) {
    // The file's size was checked against the limit before it is read.
    if (auto file = internal::CheckFile(request.path, limits.max_file_bytes); !file.ok()) {
      return file.status();
    }
    Result<std::string> content = ReadWhole(request.path);
    if (!content.ok()) return Out::Error("mesh file " + Quoted(request.path) + " cannot be read");
    cache_path = request.cache_directory + "/" + CacheName(*content, settings);
    Out cached = ReadCache(cache_path, settings, request.options.hull.max_vertices);
    if (cached.ok()) return cached;
  }
  Result<std::string> reply =
      internal::HelperReply(HelperArguments(request, limits), request.path, limits);
  if (!reply.ok()) return reply.status();
  Out parsed = ParsePiecesReply(*reply, request.options.hull.max_vertices);
  if (!parsed.ok()) return Out::Error("mesh " + Quoted(request.path) + ": " + parsed.message());
  if (!cache_path.empty()) WriteCache(request.cache_directory, cache_path, settings, *reply);
  return parsed;
}

Result<std::shared_ptr<const ConvexPieceList>> CachedMeshPieces(const MeshPiecesRequest& request,
                                                                const MeshProcessLimits& limits) {
  using Out = Result<std::shared_ptr<const ConvexPieceList>>;
  const auto key = std::make_tuple(request.path, SettingsLine(request), request.cache_directory);
  return internal::CachedByFile<ConvexPieceList>(request.path, key, limits, [&]() -> Out {
    Result<ConvexPieceList> built = LoadMeshPiecesOutOfProcess(request, limits);
    if (!built.ok()) return built.status();
    return std::make_shared<const ConvexPieceList>(std::move(built).value());
  });
}

}  // namespace rigid_body_sim::io
