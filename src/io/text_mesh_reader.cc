#include "io/text_mesh_reader.h"

#include <charconv>
#include <cstddef>
#include <limits>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace rigid_body_sim::io {
namespace {

using physics::TriangleMesh;
using physics::Vec3;

// Triangles index vertices with int.
constexpr std::size_t kMaxVertices = std::numeric_limits<int>::max();

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// The next whitespace-separated token of `line`, which is advanced past it.
std::string_view NextToken(std::string_view* line) {
  std::size_t begin = 0;
  while (begin < line->size() && IsSpace((*line)[begin])) ++begin;
  std::size_t end = begin;
  while (end < line->size() && !IsSpace((*line)[end])) ++end;
  const std::string_view token = line->substr(begin, end - begin);
  line->remove_prefix(end);
  return token;
}

// A whole token as a double, locale-free (std::from_chars), to the nearest.
bool ParseDouble(std::string_view token, double* value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), *value);
  return error == std::errc() && end == token.data() + token.size();
}

// The vertex of a "v" or "vertex" line's first three numbers, appended;
// false for a bad number or one vertex too many.
bool AppendVertex(std::string_view* rest, std::vector<Vec3>* vertices) {
  Vec3 vertex;
  for (int k = 0; k < 3; ++k) {
    if (!ParseDouble(NextToken(rest), &vertex[k])) return false;
  }
  if (vertices->size() >= kMaxVertices) return false;
  vertices->push_back(vertex);
  return true;
}

// An OBJ face corner "v", "v/vt", "v//vn" or "v/vt/vn" as a 0-based index
// into the `count` vertices read so far; negative numbers count back.
bool ParseCorner(std::string_view token, long count, long* index) {
  token = token.substr(0, token.find('/'));
  long number = 0;
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), number);
  if (error != std::errc() || end != token.data() + token.size() || number == 0) return false;
  *index = number > 0 ? number - 1 : count + number;
  return *index >= 0 && *index < count;
}

// Whether the polygon of `corners` is convex, so that a fan from its first
// corner covers it: every turn e_i x e_(i+1) along it has a non-negative
// component along its normal (Newell's, Sutherland, Sproull and Schumacker
// 1974, "A Characterization of Ten Hidden-Surface Algorithms", ACM
// Computing Surveys 6(1)). A concave face is left to assimp, which clips its
// ears.
bool IsConvexPolygon(const std::vector<Vec3>& vertices, const std::vector<long>& corners) {
  const std::size_t n = corners.size();
  Vec3 normal = Vec3::Zero();
  for (std::size_t k = 0; k < n; ++k) {
    normal += vertices[corners[k]].cross(vertices[corners[(k + 1) % n]]);
  }
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3& a = vertices[corners[k]];
    const Vec3& b = vertices[corners[(k + 1) % n]];
    const Vec3& c = vertices[corners[(k + 2) % n]];
    if ((b - a).cross(c - b).dot(normal) < 0.0) return false;
  }
  return true;
}

// Keeps the vertices the triangles use, in file order.
TriangleMesh Compact(std::vector<Vec3> vertices, std::vector<Eigen::Vector3i> triangles) {
  std::vector<int> new_index(vertices.size(), -1);
  for (const Eigen::Vector3i& triangle : triangles) {
    for (int k = 0; k < 3; ++k) new_index[triangle[k]] = 0;
  }
  TriangleMesh mesh;
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    if (new_index[i] < 0) continue;
    new_index[i] = static_cast<int>(mesh.vertices.size());
    mesh.vertices.push_back(vertices[i]);
  }
  for (Eigen::Vector3i& triangle : triangles) {
    for (int k = 0; k < 3; ++k) triangle[k] = new_index[triangle[k]];
  }
  mesh.triangles = std::move(triangles);
  return mesh;
}

// Calls `line_fn` on each line of `text`; stops at the first false.
template <typename LineFn>
bool ForEachLine(std::string_view text, LineFn line_fn) {
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    if (!line_fn(line)) return false;
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  return true;
}

}  // namespace

std::optional<TriangleMesh> ReadObjText(const std::string& text) {
  std::vector<Vec3> vertices;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<long> corners;
  const bool read = ForEachLine(text, [&](std::string_view line) {
    std::string_view rest = line;
    const std::string_view keyword = NextToken(&rest);
    if (keyword == "v") {
      if (!AppendVertex(&rest, &vertices)) return false;
    } else if (keyword == "f") {
      corners.clear();
      const long count = static_cast<long>(vertices.size());
      for (std::string_view token = NextToken(&rest); !token.empty(); token = NextToken(&rest)) {
        long index = 0;
        if (!ParseCorner(token, count, &index)) return false;
        corners.push_back(index);
      }
      if (corners.size() > 3 && !IsConvexPolygon(vertices, corners)) return false;
      for (std::size_t k = 2; k < corners.size(); ++k) {
        triangles.emplace_back(static_cast<int>(corners[0]), static_cast<int>(corners[k - 1]),
                               static_cast<int>(corners[k]));
      }
    }
    // A line continued on the next ("\\" at its end) is left to assimp.
    std::string_view trimmed = line;
    while (!trimmed.empty() && IsSpace(trimmed.back())) trimmed.remove_suffix(1);
    return trimmed.empty() || trimmed.back() != '\\';
  });
  if (!read || triangles.empty()) return std::nullopt;
  return Compact(std::move(vertices), std::move(triangles));
}

std::optional<TriangleMesh> ReadAsciiStlText(const std::string& text) {
  std::string_view head = text;
  if (NextToken(&head) != "solid") return std::nullopt;
  std::vector<Vec3> vertices;
  bool ended = false;
  const bool read = ForEachLine(text, [&](std::string_view line) {
    std::string_view rest = line;
    const std::string_view keyword = NextToken(&rest);
    if (keyword == "vertex") {
      if (!AppendVertex(&rest, &vertices)) return false;
    } else if (keyword == "endsolid") {
      ended = true;
    } else if (line.find('\0') != std::string_view::npos) {
      return false;  // binary
    }
    return true;
  });
  if (!read || !ended || vertices.empty() || vertices.size() % 3 != 0) return std::nullopt;
  // Every vertex is a facet's corner: nothing to compact.
  TriangleMesh mesh;
  for (std::size_t i = 0; i < vertices.size(); i += 3) {
    mesh.triangles.emplace_back(static_cast<int>(i), static_cast<int>(i + 1),
                                static_cast<int>(i + 2));
  }
  mesh.vertices = std::move(vertices);
  return mesh;
}

}  // namespace rigid_body_sim::io
