// Convex pieces of moving meshes from the helper process, with a disk cache
// keyed by the file's bytes and the decomposition settings (mesh_process.h).
// The cache's files are untrusted input: opened without following a link
// or blocking, checked on the descriptor, bounded, versioned and
// checksummed before the pieces parser sees them.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
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

// An entry's first line, before the version.
constexpr char kFormatName[] = "rigid_body_sim decomposition cache ";

// The collector warnings go to on this thread (MeshCacheWarnings).
thread_local MeshCacheWarnings* innermost_warnings = nullptr;

std::string Quoted(const std::string& text) { return "'" + text + "'"; }

const char* RuleName(PiecesRule rule) { return rule == PiecesRule::kAuto ? "auto" : "always"; }

// Every setting the pieces depend on, in one line; the disk cache's key
// holds it whole, so two settings never share a cache file. Its leading
// version names the decomposition algorithm: v2 keeps thin-walled cavities
// open, so the pieces that v1 cached are not reused.
std::string SettingsLine(const MeshPiecesRequest& request) {
  const DecompositionOptions& o = request.options;
  return "v2 scale " + HexFloat(request.scale.x()) + " " + HexFloat(request.scale.y()) + " " +
         HexFloat(request.scale.z()) + " rule " + RuleName(request.rule) + " voxels " +
         std::to_string(o.voxel_count) + " pieces " + std::to_string(o.max_pieces) + " concavity " +
         HexFloat(o.max_concavity) + " balance " + HexFloat(o.balance_weight) + " merge " +
         HexFloat(o.merge_volume) + " ratio " + HexFloat(o.convex_ratio) + " hull " +
         std::to_string(o.hull.max_vertices) + " " + HexFloat(o.hull.degenerate_tolerance);
}

// 64-bit FNV-1a (Fowler, Noll, Vo), twice with different offset bases, and
// the byte count: a 128-bit name for the file's content plus the settings.
// The name did not change with the entry format, so a new entry replaces
// the old one.
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

// The checksum of an entry's body: it tells a torn or altered entry from a
// good one (not a forged one: anyone who can write the directory can write
// a good entry).
std::uint64_t Fnv1a(const std::string& bytes) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const unsigned char byte : bytes) hash = (hash ^ byte) * 0x100000001b3ULL;
  return hash;
}

std::string Hex64(std::uint64_t value) {
  char text[24];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(value));
  return text;
}

// Reads an entry's "body <bytes> <checksum>" line (without its newline)
// strictly: up to 9 decimal digits, one space, 16 lowercase hex digits.
bool ParseBodyLine(const std::string& line, std::size_t* bytes, std::uint64_t* checksum) {
  const std::string prefix = "body ";
  const std::size_t space = line.find(' ', prefix.size());
  if (line.compare(0, prefix.size(), prefix) != 0 || space == std::string::npos) return false;
  const std::string count = line.substr(prefix.size(), space - prefix.size());
  const std::string hash = line.substr(space + 1);
  if (count.empty() || count.size() > 9 || hash.size() != 16) return false;
  *bytes = 0;
  for (const char c : count) {
    if (c < '0' || c > '9') return false;
    *bytes = *bytes * 10 + static_cast<std::size_t>(c - '0');
  }
  *checksum = 0;
  for (const char c : hash) {
    const int digit = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
    if (digit < 0) return false;
    *checksum = (*checksum << 4) | static_cast<std::uint64_t>(digit);
  }
  return true;
}

// Why an entry's first line is not this format's: another version, the
// unversioned format, or no entry of ours at all. Shows no file bytes but a
// short version number.
std::string WrongFormat(const std::string& line) {
  if (line.rfind(kFormatName, 0) == 0) {
    const std::string version = line.substr(std::strlen(kFormatName));
    const bool readable =
        !version.empty() && version.size() <= 9 &&
        std::all_of(version.begin(), version.end(), [](char c) { return c >= '0' && c <= '9'; });
    return "it is format version " + (readable ? version : std::string("(unreadable)")) + ", not " +
           std::to_string(kCacheFormatVersion);
  }
  if (line.rfind("key ", 0) == 0) {
    return "it is in the format before version " + std::to_string(kCacheFormatVersion);
  }
  return "it is not a decomposition cache entry";
}

// An entry written before the format had a version: stale, not suspect.
bool IsUnversionedEntry(const std::string& text) { return text.rfind("key ", 0) == 0; }

Result<std::string> ReadWhole(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return Result<std::string>::Error("cannot be read");
  std::ostringstream contents;
  contents << file.rdbuf();
  return contents.str();
}

// A file descriptor, closed when it goes out of scope.
class ScopedFd {
 public:
  explicit ScopedFd(int fd) : fd_(fd) {}
  ~ScopedFd() {
    if (fd_ >= 0) ::close(fd_);
  }
  ScopedFd(const ScopedFd&) = delete;
  ScopedFd& operator=(const ScopedFd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

// Makes each missing directory of `path` (mode 0700) and opens the last,
// refusing one that is not a directory or is a symbolic link (ENOTDIR,
// ELOOP): what is checked here is what the entries are reached through.
// Returns -1 with `problem` set when the directory cannot be used.
int OpenCacheDirectory(std::string path, std::string* problem) {
  // A trailing slash would make open() follow a link in the last component.
  while (path.size() > 1 && path.back() == '/') path.pop_back();
  for (std::size_t slash = path.find('/', 1); slash != std::string::npos;
       slash = path.find('/', slash + 1)) {
    ::mkdir(path.substr(0, slash).c_str(), 0700);  // EEXIST for those that exist
  }
  ::mkdir(path.c_str(), 0700);
  const int fd = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd >= 0) return fd;
  if (errno == ELOOP) {
    *problem = "it is a symbolic link";
  } else if (errno == ENOTDIR) {
    *problem = "it is not a directory";
  } else {
    *problem = std::string("it cannot be opened: ") + std::strerror(errno);
  }
  return -1;
}

bool WriteAll(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t count = ::write(fd, text.data() + done, text.size() - done);
    if (count < 0 && errno == EINTR) continue;
    if (count <= 0) return false;
    done += static_cast<std::size_t>(count);
  }
  return true;
}

// A request's entry in the disk cache, reached through the descriptor of
// its directory, so the directory checked is the one used.
class DiskCacheEntry {
 public:
  // Opens `directory`, made when missing; one that cannot be used is
  // warned about and leaves the entry unused.
  DiskCacheEntry(const std::string& directory, std::string name)
      : name_(std::move(name)), path_(directory + "/" + name_) {
    std::string problem;
    directory_ = OpenCacheDirectory(directory, &problem);
    if (directory_ < 0) {
      MeshCacheWarnings::Report("decomposition cache directory " + Quoted(directory) +
                                " is not used: " + problem);
    }
  }
  ~DiskCacheEntry() {
    if (directory_ >= 0) ::close(directory_);
  }
  DiskCacheEntry(const DiskCacheEntry&) = delete;
  DiskCacheEntry& operator=(const DiskCacheEntry&) = delete;

  // The pieces a good entry holds; nothing when there is no entry, or a
  // bad one, which is warned about with its path and the reason.
  std::optional<ConvexPieceList> Read(const std::string& settings, int max_vertices) const {
    if (directory_ < 0) return std::nullopt;
    Result<std::optional<std::string>> text = ReadText();
    Result<ConvexPieceList> pieces = Result<ConvexPieceList>::Error("unread");
    if (text.ok()) {
      if (!text->has_value() || IsUnversionedEntry(**text)) return std::nullopt;
      pieces = ParseCacheEntry(**text, settings, max_vertices);
      if (pieces.ok()) return std::move(pieces).value();
    }
    MeshCacheWarnings::Report(
        "decomposition cache entry " + Quoted(path_) +
        " is bad; it is ignored and rebuilt: " + (text.ok() ? pieces.message() : text.message()));
    return std::nullopt;
  }

  // Writes the entry to a file of its own, then renames it over the name,
  // so a reader never sees half an entry and concurrent writers do not
  // mix. Any failure leaves the entry unwritten.
  void Write(const std::string& settings, const std::string& reply) const {
    if (directory_ < 0) return;
    const std::string text = FormatCacheEntry(settings, reply);
    if (text.size() > kMaxCacheEntryBytes) return;  // it would be refused when read
    static std::atomic<int> counter{0};
    const std::string temporary =
        name_ + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter.fetch_add(1));
    const int fd = ::openat(directory_, temporary.c_str(),
                            O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (fd < 0) return;
    const bool written = WriteAll(fd, text);
    const bool closed = ::close(fd) == 0;
    if (!written || !closed || !RenameOverEntry(temporary)) {
      ::unlinkat(directory_, temporary.c_str(), 0);
    }
  }

 private:
  // The entry's text; none when there is no entry; an error saying why
  // when it is not a regular file of at most kMaxCacheEntryBytes. Neither
  // a link is followed nor a FIFO waited on, and the checks are made on
  // the descriptor read from.
  Result<std::optional<std::string>> ReadText() const {
    using Out = Result<std::optional<std::string>>;
    const ScopedFd fd(
        ::openat(directory_, name_.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC));
    if (fd.get() < 0) {
      if (errno == ENOENT) return std::optional<std::string>();
      if (errno == ELOOP) return Out::Error("it is a symbolic link");
      return Out::Error(std::string("it cannot be opened: ") + std::strerror(errno));
    }
    struct stat info {};
    if (::fstat(fd.get(), &info) != 0) {
      return Out::Error(std::string("it cannot be examined: ") + std::strerror(errno));
    }
    if (!S_ISREG(info.st_mode)) return Out::Error("it is not a regular file");
    if (static_cast<std::uint64_t>(info.st_size) > kMaxCacheEntryBytes) {
      return Out::Error("its size " + std::to_string(info.st_size) + " bytes is above the limit " +
                        std::to_string(kMaxCacheEntryBytes));
    }
    // Never more than the limit, even from a file that grew since fstat.
    std::string text;
    text.reserve(static_cast<std::size_t>(info.st_size));
    char buffer[65536];
    while (text.size() < kMaxCacheEntryBytes) {
      const std::size_t wanted = std::min(sizeof(buffer), kMaxCacheEntryBytes - text.size());
      const ssize_t count = ::read(fd.get(), buffer, wanted);
      if (count < 0 && errno == EINTR) continue;
      if (count < 0) return Out::Error(std::string("it cannot be read: ") + std::strerror(errno));
      if (count == 0) break;
      text.append(buffer, static_cast<std::size_t>(count));
    }
    return std::optional<std::string>(std::move(text));
  }

  // A bad entry that is an empty directory gives way to the new one; a
  // directory with anything in it is left alone.
  bool RenameOverEntry(const std::string& temporary) const {
    if (::renameat(directory_, temporary.c_str(), directory_, name_.c_str()) == 0) return true;
    return errno == EISDIR && ::unlinkat(directory_, name_.c_str(), AT_REMOVEDIR) == 0 &&
           ::renameat(directory_, temporary.c_str(), directory_, name_.c_str()) == 0;
  }

  int directory_ = -1;
  std::string name_;
  std::string path_;  // for warnings
};

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

MeshCacheWarnings::MeshCacheWarnings() : outer_(innermost_warnings) { innermost_warnings = this; }

MeshCacheWarnings::~MeshCacheWarnings() { innermost_warnings = outer_; }

void MeshCacheWarnings::Report(std::string warning) {
  if (innermost_warnings != nullptr) innermost_warnings->warnings_.push_back(std::move(warning));
}

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

std::string FormatCacheEntry(const std::string& settings, const std::string& reply) {
  return kFormatName + std::to_string(kCacheFormatVersion) + "\nkey " + settings + "\nbody " +
         std::to_string(reply.size()) + " " + Hex64(Fnv1a(reply)) + "\n" + reply;
}

Result<ConvexPieceList> ParseCacheEntry(const std::string& text, const std::string& settings,
                                        int max_vertices) {
  using Out = Result<ConvexPieceList>;
  if (text.size() > kMaxCacheEntryBytes) {
    return Out::Error("it is " + std::to_string(text.size()) + " bytes, above the limit " +
                      std::to_string(kMaxCacheEntryBytes));
  }
  std::size_t at = 0;
  // The next line from `at`, without its newline; false when none ends.
  const auto next_line = [&text, &at](std::string* line) {
    const std::size_t end = text.find('\n', at);
    if (end == std::string::npos) return false;
    *line = text.substr(at, end - at);
    at = end + 1;
    return true;
  };
  std::string line;
  if (!next_line(&line)) return Out::Error("it has no complete first line");
  if (line != kFormatName + std::to_string(kCacheFormatVersion)) {
    return Out::Error(WrongFormat(line));
  }
  if (!next_line(&line) || line != "key " + settings) return Out::Error("it holds other settings");
  std::size_t bytes = 0;
  std::uint64_t checksum = 0;
  if (!next_line(&line) || !ParseBodyLine(line, &bytes, &checksum)) {
    return Out::Error("its 'body <bytes> <checksum>' line is malformed");
  }
  const std::string body = text.substr(at);
  if (body.size() != bytes) {
    return Out::Error("its body is " + std::to_string(body.size()) + " bytes, its header says " +
                      std::to_string(bytes));
  }
  if (Fnv1a(body) != checksum) {
    return Out::Error("its body's checksum is " + Hex64(Fnv1a(body)) + ", its header says " +
                      Hex64(checksum));
  }
  Out pieces = ParsePiecesReply(body, max_vertices);
  if (!pieces.ok()) return Out::Error("its pieces do not parse: " + pieces.message());
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
  const int max_vertices = request.options.hull.max_vertices;
  std::optional<DiskCacheEntry> entry;
  if (!request.cache_directory.empty()) {
    // The file's size was checked against the limit before it is read.
    if (auto file = internal::CheckFile(request.path, limits.max_file_bytes); !file.ok()) {
      return file.status();
    }
    Result<std::string> content = ReadWhole(request.path);
    if (!content.ok()) return Out::Error("mesh file " + Quoted(request.path) + " cannot be read");
    entry.emplace(request.cache_directory, CacheName(*content, settings));
    if (std::optional<ConvexPieceList> cached = entry->Read(settings, max_vertices)) {
      return std::move(*cached);
    }
  }
  Result<std::string> reply =
      internal::HelperReply(HelperArguments(request, limits), request.path, limits);
  if (!reply.ok()) return reply.status();
  Out parsed = ParsePiecesReply(*reply, max_vertices);
  if (!parsed.ok()) return Out::Error("mesh " + Quoted(request.path) + ": " + parsed.message());
  if (entry.has_value()) entry->Write(settings, *reply);
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
