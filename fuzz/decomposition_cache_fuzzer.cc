// libFuzzer harness for the convex-decomposition disk cache's entries,
// which are untrusted files (mesh_process.h). The bytes are, in turn: an
// entry, which ParseCacheEntry must refuse with a reason or accept, and an
// accepted one must come back the same when formatted again; and a body,
// wrapped in a good header (so it passes the length and checksum the
// fuzzer could hardly forge), which must parse as ParsePiecesReply parses
// it alone, and must be refused when the entry is cut short or grown.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "rigid_body_sim/io/mesh_process.h"

namespace {

namespace io = rigid_body_sim::io;

// The seeds in fuzz/corpus/decomposition_cache were made with these.
constexpr char kSettings[] = "v1 fuzz settings";
constexpr int kMaxVertices = 256;

bool SamePieces(const io::ConvexPieceList& a, const io::ConvexPieceList& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].vertices != b[i].vertices || a[i].faces.size() != b[i].faces.size()) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const auto entry = io::ParseCacheEntry(text, kSettings, kMaxVertices);
  if (!entry.ok() && entry.message().empty()) std::abort();  // a refusal must say why
  if (entry.ok()) {
    const std::string again = io::FormatCacheEntry(kSettings, io::FormatPiecesReply(*entry));
    const auto reparsed = io::ParseCacheEntry(again, kSettings, kMaxVertices);
    if (!reparsed.ok() || !SamePieces(*entry, *reparsed)) std::abort();
  }

  const std::string wrapped = io::FormatCacheEntry(kSettings, text);
  const auto body = io::ParseCacheEntry(wrapped, kSettings, kMaxVertices);
  const auto alone = io::ParsePiecesReply(text, kMaxVertices);
  if (body.ok() != alone.ok() || (body.ok() && !SamePieces(*body, *alone))) std::abort();
  const std::size_t cut = 1 + (size == 0 ? 0 : data[0] % 64);
  if (cut <= wrapped.size() &&
      io::ParseCacheEntry(wrapped.substr(0, wrapped.size() - cut), kSettings, kMaxVertices).ok()) {
    std::abort();
  }
  if (io::ParseCacheEntry(wrapped + "\n", kSettings, kMaxVertices).ok()) std::abort();
  if (io::ParseCacheEntry(wrapped, "v1 other settings", kMaxVertices).ok()) std::abort();
  return 0;
}
