// The convex-decomposition disk cache read as untrusted input
// (mesh_process.h): an entry that is a link to /dev/zero, a FIFO, a
// directory, altered, torn, of another version or settings, or too large is
// ignored with one warning naming it, within a bound; the helper's pieces
// are used and written over it, and the next request reads them with no
// helper.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "rigid_body_sim/io/mesh_process.h"
#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"

namespace rigid_body_sim::io {
namespace {

namespace fs = std::filesystem;
using physics::Result;

const std::string kDataDir = RBS_TEST_DATA_DIR;
// Concave: decomposed into several pieces by default.
const std::string kMesh = kDataDir + "/l_bracket.stl";
// Every request here, the helper's run included, answers within this.
constexpr double kMaxSeconds = 5.0;

MeshProcessLimits HelperLimits() {
  MeshProcessLimits limits;
  limits.helper_path = RBS_MESH_HELPER;
  return limits;
}

// Only the disk cache can answer under these limits.
MeshProcessLimits NoHelper() {
  MeshProcessLimits limits;
  limits.helper_path = "/nonexistent/rbs_mesh_helper";
  return limits;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

void WriteFile(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

void ExpectSamePieces(const ConvexPieceList& a, const ConvexPieceList& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].vertices, b[i].vertices) << "piece " << i;
    EXPECT_EQ(a[i].faces.size(), b[i].faces.size()) << "piece " << i;
  }
}

// One request's answer, the cache's warnings about it and its wall time.
struct Outcome {
  Result<ConvexPieceList> pieces;
  std::vector<std::string> warnings;
  double seconds;
};

Outcome Load(const MeshPiecesRequest& request, const MeshProcessLimits& limits) {
  const MeshCacheWarnings warnings;
  const auto start = std::chrono::steady_clock::now();
  Result<ConvexPieceList> pieces = LoadMeshPiecesOutOfProcess(request, limits);
  const std::chrono::duration<double> seconds = std::chrono::steady_clock::now() - start;
  return {std::move(pieces), warnings.warnings(), seconds.count()};
}

// The helper's pieces without a cache and the entry a cached request
// writes for them, made once for every test.
struct Reference {
  fs::path root;
  ConvexPieceList pieces;
  std::string entry_name;
  std::string entry_text;
};
const Reference* reference = nullptr;

class DecompositionCacheTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto* made = new Reference;
    made->root =
        fs::temp_directory_path() / ("rbs_decomposition_cache_test_" + std::to_string(::getpid()));
    fs::remove_all(made->root);
    fs::create_directories(made->root);
    MeshPiecesRequest request;
    request.path = kMesh;
    const Result<ConvexPieceList> uncached = LoadMeshPiecesOutOfProcess(request, HelperLimits());
    ASSERT_TRUE(uncached.ok()) << uncached.message();
    made->pieces = *uncached;
    request.cache_directory = (made->root / "first").string();
    ASSERT_TRUE(LoadMeshPiecesOutOfProcess(request, HelperLimits()).ok());
    for (const fs::directory_entry& entry : fs::directory_iterator(request.cache_directory)) {
      ASSERT_TRUE(made->entry_name.empty()) << "a second file " << entry.path();
      made->entry_name = entry.path().filename().string();
      made->entry_text = ReadFile(entry.path());
    }
    reference = made;
  }

  static void TearDownTestSuite() {
    if (reference != nullptr) fs::remove_all(reference->root);
    delete reference;
    reference = nullptr;
  }

  // A cache directory of the test's own holding the good entry.
  void SetUp() override {
    ASSERT_NE(reference, nullptr);
    ASSERT_GE(reference->pieces.size(), 2u);
    directory_ = reference->root / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(directory_);
    request_.path = kMesh;
    request_.cache_directory = directory_.string();
    entry_ = directory_ / reference->entry_name;
    WriteFile(entry_, reference->entry_text);
  }

  // The settings line the entry holds (after "key ").
  static std::string Settings() {
    const std::string& text = reference->entry_text;
    const std::size_t key = text.find("\nkey ") + 5;
    return text.substr(key, text.find('\n', key) - key);
  }

  // The entry's text with `from` (once) replaced by `to`.
  static std::string Edited(const std::string& from, const std::string& to) {
    std::string text = reference->entry_text;
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? text : text.replace(at, from.size(), to);
  }

  // The request, the entry bad: answered by the helper within kMaxSeconds
  // with its pieces and one warning naming the entry and `reason`; the
  // entry is then good.
  void ExpectRebuiltWithOneWarning(const std::string& reason) {
    const Outcome rebuilt = Load(request_, HelperLimits());
    ASSERT_TRUE(rebuilt.pieces.ok()) << rebuilt.pieces.message();
    EXPECT_LT(rebuilt.seconds, kMaxSeconds);
    ExpectSamePieces(*rebuilt.pieces, reference->pieces);
    ASSERT_EQ(rebuilt.warnings.size(), 1u);
    EXPECT_NE(rebuilt.warnings[0].find("'" + entry_.string() + "'"), std::string::npos)
        << rebuilt.warnings[0];
    EXPECT_NE(rebuilt.warnings[0].find(reason), std::string::npos) << rebuilt.warnings[0];
    ExpectGoodEntry();
  }

  // The entry is a regular file, as written afresh, and answers alone.
  void ExpectGoodEntry() {
    struct stat info {};
    ASSERT_EQ(::lstat(entry_.c_str(), &info), 0);
    EXPECT_TRUE(S_ISREG(info.st_mode));
    EXPECT_EQ(ReadFile(entry_), reference->entry_text);
    const Outcome cached = Load(request_, NoHelper());
    ASSERT_TRUE(cached.pieces.ok()) << cached.pieces.message();
    EXPECT_LT(cached.seconds, kMaxSeconds);
    EXPECT_TRUE(cached.warnings.empty()) << cached.warnings.front();
    ExpectSamePieces(*cached.pieces, reference->pieces);
  }

  fs::path directory_;
  fs::path entry_;
  MeshPiecesRequest request_;
};

TEST_F(DecompositionCacheTest, EntryIsTheVersionedChecksummedHelperReply) {
  const std::string& text = reference->entry_text;
  EXPECT_EQ(text.rfind("rigid_body_sim decomposition cache 2\nkey v2 scale ", 0), 0u) << text;
  const std::size_t body_line = text.find("\nbody ") + 1;
  const std::string body = text.substr(text.find('\n', body_line) + 1);
  EXPECT_EQ(body.rfind("pieces ", 0), 0u);
  EXPECT_EQ(text, FormatCacheEntry(Settings(), body));
  EXPECT_LE(text.size(), kMaxCacheEntryBytes);
  ExpectGoodEntry();
}

TEST_F(DecompositionCacheTest, MissingEntryIsBuiltWithoutAWarningInAPrivateDirectory) {
  request_.cache_directory = (directory_ / "made" / "here").string();
  const Outcome built = Load(request_, HelperLimits());
  ASSERT_TRUE(built.pieces.ok()) << built.pieces.message();
  EXPECT_TRUE(built.warnings.empty()) << built.warnings.front();
  ExpectSamePieces(*built.pieces, reference->pieces);
  const fs::path entry = fs::path(request_.cache_directory) / reference->entry_name;
  EXPECT_EQ(ReadFile(entry), reference->entry_text);
  struct stat info {};
  ASSERT_EQ(::stat(request_.cache_directory.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0700u);
  ASSERT_EQ(::stat(entry.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600u);
}

TEST_F(DecompositionCacheTest, SymlinkToDevZeroIsNotRead) {
  fs::remove(entry_);
  fs::create_symlink("/dev/zero", entry_);
  ExpectRebuiltWithOneWarning("it is a symbolic link");
}

TEST_F(DecompositionCacheTest, FifoIsNotWaitedOn) {
  fs::remove(entry_);
  ASSERT_EQ(::mkfifo(entry_.c_str(), 0600), 0);
  ExpectRebuiltWithOneWarning("it is not a regular file");
}

TEST_F(DecompositionCacheTest, EmptyDirectoryIsReplaced) {
  fs::remove(entry_);
  fs::create_directory(entry_);
  ExpectRebuiltWithOneWarning("it is not a regular file");
}

TEST_F(DecompositionCacheTest, FlippedBodyByteFailsTheChecksum) {
  std::string text = reference->entry_text;
  text[text.size() - 10] ^= 0x01;
  WriteFile(entry_, text);
  ExpectRebuiltWithOneWarning("checksum");
}

TEST_F(DecompositionCacheTest, TruncatedEntryFailsTheLength) {
  WriteFile(entry_, reference->entry_text.substr(0, reference->entry_text.size() - 100));
  ExpectRebuiltWithOneWarning("its body is");
}

TEST_F(DecompositionCacheTest, OtherVersionIsRebuilt) {
  WriteFile(entry_, Edited("decomposition cache 2\n", "decomposition cache 1\n"));
  ExpectRebuiltWithOneWarning("format version 1, not 2");
}

TEST_F(DecompositionCacheTest, OtherSettingsAreRebuilt) {
  WriteFile(entry_, Edited("\nkey v2 scale ", "\nkey v2 scale 0x1p+1 "));
  ExpectRebuiltWithOneWarning("it holds other settings");
}

TEST_F(DecompositionCacheTest, EntryAboveTheSizeLimitIsNotRead) {
  std::string text = reference->entry_text;
  text.resize(kMaxCacheEntryBytes + 1, ' ');
  WriteFile(entry_, text);
  ExpectRebuiltWithOneWarning("is above the limit");
}

TEST_F(DecompositionCacheTest, UnparsablePiecesAreRebuilt) {
  WriteFile(entry_, FormatCacheEntry(Settings(), "pieces 2\nhull 4 4\n"));
  ExpectRebuiltWithOneWarning("its pieces do not parse");
}

// The format before versions ("key <settings>", then the body) is stale,
// not suspect: rebuilt without a warning.
TEST_F(DecompositionCacheTest, UnversionedEntryIsRebuiltSilently) {
  const std::string& text = reference->entry_text;
  const std::string body = text.substr(text.find('\n', text.find("\nbody ") + 1) + 1);
  WriteFile(entry_, "key " + Settings() + "\n" + body);
  ASSERT_EQ(ReadFile(entry_).rfind("key v2 scale ", 0), 0u);
  const Outcome rebuilt = Load(request_, HelperLimits());
  ASSERT_TRUE(rebuilt.pieces.ok()) << rebuilt.pieces.message();
  EXPECT_LT(rebuilt.seconds, kMaxSeconds);
  EXPECT_TRUE(rebuilt.warnings.empty()) << rebuilt.warnings.front();
  ExpectSamePieces(*rebuilt.pieces, reference->pieces);
  ExpectGoodEntry();
}

// A directory with anything in it is no entry of ours to remove: the
// helper answers each time, with the warning each time.
TEST_F(DecompositionCacheTest, DirectoryWithContentsIsLeftAlone) {
  fs::remove(entry_);
  fs::create_directory(entry_);
  WriteFile(entry_ / "keep", "someone's");
  for (int run = 0; run < 2; ++run) {
    const Outcome outcome = Load(request_, HelperLimits());
    ASSERT_TRUE(outcome.pieces.ok()) << outcome.pieces.message();
    ExpectSamePieces(*outcome.pieces, reference->pieces);
    EXPECT_EQ(outcome.warnings.size(), 1u);
  }
  EXPECT_EQ(ReadFile(entry_ / "keep"), "someone's");
  EXPECT_EQ(std::distance(fs::directory_iterator(directory_), fs::directory_iterator()), 1);
}

TEST_F(DecompositionCacheTest, CacheDirectoryThatIsAFileOrALinkIsNotUsed) {
  const fs::path file = directory_ / "plain_file";
  WriteFile(file, "not a directory");
  const fs::path link = directory_ / "link";
  fs::create_directory_symlink(directory_, link);
  for (const fs::path& cache : {file, link}) {
    request_.cache_directory = cache.string();
    const Outcome outcome = Load(request_, HelperLimits());
    ASSERT_TRUE(outcome.pieces.ok()) << outcome.pieces.message();
    ExpectSamePieces(*outcome.pieces, reference->pieces);
    ASSERT_EQ(outcome.warnings.size(), 1u) << cache;
    EXPECT_NE(outcome.warnings[0].find("'" + cache.string() + "' is not used"), std::string::npos)
        << outcome.warnings[0];
    // Not even the good entry behind the link answers without the helper.
    EXPECT_FALSE(Load(request_, NoHelper()).pieces.ok());
  }
  EXPECT_EQ(ReadFile(file), "not a directory");
}

// The node's path: a URDF's concave mesh through CachedMeshPieces with a
// bad entry carries the warning into LoadedModel::warnings, once.
TEST_F(DecompositionCacheTest, UrdfLoadReportsTheBadEntryInTheModelWarnings) {
  fs::remove(entry_);
  fs::create_symlink("/dev/zero", entry_);
  UrdfLoadOptions options;
  const MeshProcessLimits limits = HelperLimits();
  const std::string cache_directory = request_.cache_directory;
  options.mesh_pieces_loader = [limits, cache_directory](
                                   const std::string& path, const physics::Vec3& scale,
                                   const DecompositionOptions& decomposition, PiecesRule rule) {
    MeshPiecesRequest request;
    request.path = path;
    request.scale = scale;
    request.options = decomposition;
    request.rule = rule;
    request.cache_directory = cache_directory;
    return CachedMeshPieces(request, limits);
  };
  const std::string xml =
      "<robot name='m'><link name='base'><collision><geometry><mesh filename='" + kMesh +
      "'/></geometry></collision></link></robot>";
  const auto count_cache_warnings = [this](const LoadedModel& model) {
    int count = 0;
    for (const std::string& warning : model.warnings) {
      if (warning.find("'" + entry_.string() + "'") != std::string::npos) ++count;
    }
    return count;
  };
  const Result<LoadedModel> first = LoadUrdfString(xml, options);
  ASSERT_TRUE(first.ok()) << first.message();
  EXPECT_EQ(first->shapes.size(), reference->pieces.size());
  EXPECT_EQ(count_cache_warnings(*first), 1);
  const Result<LoadedModel> second = LoadUrdfString(xml, options);
  ASSERT_TRUE(second.ok()) << second.message();
  EXPECT_EQ(count_cache_warnings(*second), 0);
  ExpectGoodEntry();
}

TEST(DecompositionCacheEntryTest, FormattedEntryParsesAndEveryCutIsRefused) {
  const Result<physics::ConvexPolyhedron> box =
      physics::TryMakeBoxPolyhedron(physics::Vec3(1.0, 2.0, 3.0));
  ASSERT_TRUE(box.ok()) << box.message();
  const std::string reply = FormatPiecesReply({*box, *box});
  const std::string entry = FormatCacheEntry("settings", reply);
  const Result<ConvexPieceList> parsed = ParseCacheEntry(entry, "settings", 256);
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  ExpectSamePieces(*parsed, {*box, *box});
  EXPECT_FALSE(ParseCacheEntry(entry, "other settings", 256).ok());
  for (std::size_t size = 0; size < entry.size(); ++size) {
    EXPECT_FALSE(ParseCacheEntry(entry.substr(0, size), "settings", 256).ok()) << size;
  }
  EXPECT_FALSE(ParseCacheEntry(entry + " ", "settings", 256).ok());
  const Result<ConvexPieceList> refusal =
      ParseCacheEntry(FormatCacheEntry("settings", "error no\n"), "settings", 256);
  ASSERT_FALSE(refusal.ok());
  EXPECT_EQ(refusal.message(), "its pieces do not parse: no");
}

}  // namespace
}  // namespace rigid_body_sim::io
