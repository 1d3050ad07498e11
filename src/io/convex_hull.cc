#include "rigid_body_sim/io/convex_hull.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string>
#include <utility>

extern "C" {
#include <libqhull_r/libqhull_r.h>
#include <libqhull_r/poly_r.h>
}

namespace rigid_body_sim::io {
namespace {

using physics::ConvexPolyhedron;
using physics::Result;
using physics::Vec3;

// Hull vertices and faces as indices into the caller's point array.
struct RawHull {
  std::vector<int> vertex_ids;
  std::vector<std::vector<int>> faces;  // counter-clockwise seen from outside
};

// Collects qhull's error output in memory, so a failure can be reported in
// the returned message instead of on stderr.
class ErrorStream {
 public:
  ErrorStream() : file_(open_memstream(&buffer_, &size_)) {}
  ~ErrorStream() {
    if (file_ != nullptr) std::fclose(file_);
    std::free(buffer_);
  }
  ErrorStream(const ErrorStream&) = delete;
  ErrorStream& operator=(const ErrorStream&) = delete;

  FILE* file() const { return file_; }
  std::string Text() {
    if (file_ == nullptr) return {};
    std::fflush(file_);
    std::string text(buffer_, size_);
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    return text;
  }

 private:
  char* buffer_ = nullptr;
  size_t size_ = 0;
  FILE* file_ = nullptr;
};

// Orders the vertices of one planar facet counter-clockwise about its outward
// normal by their angle around the facet centroid in the facet plane.
void SortCounterClockwise(const std::vector<Vec3>& points, const Vec3& normal,
                          std::vector<int>* face) {
  Vec3 centroid = Vec3::Zero();
  for (int id : *face) centroid += points[id];
  centroid /= static_cast<double>(face->size());
  Vec3 axis_u = points[face->front()] - centroid;
  axis_u -= normal.dot(axis_u) * normal;
  axis_u.normalize();
  const Vec3 axis_w = normal.cross(axis_u);
  std::vector<std::pair<double, int>> by_angle;
  by_angle.reserve(face->size());
  for (int id : *face) {
    const Vec3 offset = points[id] - centroid;
    by_angle.emplace_back(std::atan2(axis_w.dot(offset), axis_u.dot(offset)), id);
  }
  std::sort(by_angle.begin(), by_angle.end());
  for (size_t i = 0; i < by_angle.size(); ++i) (*face)[i] = by_angle[i].second;
}

// The lower and upper corners of the bounding box of the points selected by
// `ids` (at least one).
std::pair<Vec3, Vec3> BoundsOf(const std::vector<Vec3>& points, const std::vector<int>& ids) {
  Vec3 low = points[ids.front()];
  Vec3 high = low;
  for (int id : ids) {
    low = low.cwiseMin(points[id]);
    high = high.cwiseMax(points[id]);
  }
  return {low, high};
}

// Runs reentrant qhull (Barber, Dobkin, Huhdanpaa 1996, "The Quickhull
// Algorithm for Convex Hulls") on the points selected by `ids`, with the
// qhull command line `options`. The default options pre-merge facets that
// are coplanar within round-off ('C-0'), so flat regions come out as single
// non-simplicial facets. qh_new_qhull traps qhull's internal errors with
// its own setjmp and returns an exit code; the facet walk afterwards calls
// nothing that can raise an error.
Result<RawHull> RunQhull(const std::vector<Vec3>& points, const std::vector<int>& ids,
                         const char* options = "qhull") {
  // Centring the coordinates keeps qhull's round-off small for meshes that
  // are far from their origin.
  const auto [low, high] = BoundsOf(points, ids);
  const Vec3 center = 0.5 * (low + high);
  std::vector<coordT> coordinates;
  coordinates.reserve(3 * ids.size());
  for (int id : ids) {
    const Vec3 centred = points[id] - center;
    coordinates.insert(coordinates.end(), {centred.x(), centred.y(), centred.z()});
  }

  ErrorStream errors;
  qhT qh_storage;
  qhT* qh = &qh_storage;
  qh_zero(qh, errors.file());
  std::string command = options;
  const int exit_code = qh_new_qhull(qh, 3, static_cast<int>(ids.size()), coordinates.data(), False,
                                     command.data(), nullptr, errors.file());
  std::optional<RawHull> hull;
  std::string failure;
  if (exit_code != 0) {
    failure = "qhull failed (exit code " + std::to_string(exit_code) + "): " + errors.Text();
  } else {
    hull.emplace();
    facetT* facet;
    vertexT* vertex;
    vertexT** vertexp;
    FORALLfacets {
      std::vector<int> face;
      FOREACHvertex_(facet->vertices) { face.push_back(ids[qh_pointid(qh, vertex->point)]); }
      const Vec3 normal(facet->normal[0], facet->normal[1], facet->normal[2]);
      SortCounterClockwise(points, normal, &face);
      hull->vertex_ids.insert(hull->vertex_ids.end(), face.begin(), face.end());
      hull->faces.push_back(std::move(face));
    }
    std::sort(hull->vertex_ids.begin(), hull->vertex_ids.end());
    hull->vertex_ids.erase(std::unique(hull->vertex_ids.begin(), hull->vertex_ids.end()),
                           hull->vertex_ids.end());
  }
  qh_freeqhull(qh, !qh_ALL);
  int current_long = 0;
  int total_long = 0;
  qh_memfreeshort(qh, &current_long, &total_long);
  if (!hull) return Result<RawHull>::Error(failure);
  return *std::move(hull);
}

// Index of the point furthest from `origin`.
int Furthest(const std::vector<Vec3>& points, const Vec3& origin) {
  int best = 0;
  double best_distance = -1.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const double distance = (points[i] - origin).squaredNorm();
    if (distance > best_distance) {
      best_distance = distance;
      best = static_cast<int>(i);
    }
  }
  return best;
}

// Refuses input qhull cannot hull in 3-d, with a message for the caller:
// too few points, non-finite coordinates, and point sets that are (within
// tolerance * bounding-box diagonal) a single point, a line or a plane. The
// test grows a simplex from extreme points: the furthest pair, the point
// furthest from their line, the point furthest from their plane.
physics::Status CheckNotDegenerate(const std::vector<Vec3>& points, double tolerance) {
  if (points.size() < 4) {
    return physics::Status::Error("convex hull needs at least 4 points, got " +
                                  std::to_string(points.size()));
  }
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      return physics::Status::Error("convex hull input point " + std::to_string(i) +
                                    " is not finite");
    }
  }
  Vec3 low = points.front();
  Vec3 high = low;
  for (const Vec3& point : points) {
    low = low.cwiseMin(point);
    high = high.cwiseMax(point);
  }
  const double threshold = tolerance * (high - low).norm();
  const int a = Furthest(points, points.front());
  const int b = Furthest(points, points[a]);
  const Vec3 line = points[b] - points[a];
  if (line.norm() <= threshold || line.norm() == 0.0) {
    return physics::Status::Error("convex hull input points all coincide");
  }
  const Vec3 line_direction = line.normalized();
  double line_distance = 0.0;
  int c = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const double distance = line_direction.cross(points[i] - points[a]).norm();
    if (distance > line_distance) {
      line_distance = distance;
      c = static_cast<int>(i);
    }
  }
  if (line_distance <= threshold) {
    return physics::Status::Error("convex hull input points all lie on a line");
  }
  const Vec3 normal = line.cross(points[c] - points[a]).normalized();
  double plane_distance = 0.0;
  for (const Vec3& point : points) {
    plane_distance = std::max(plane_distance, std::abs(normal.dot(point - points[a])));
  }
  if (plane_distance <= threshold) {
    return physics::Status::Error(
        "convex hull input points all lie in a plane; a flat shape needs thickness");
  }
  return physics::Status::Ok();
}

// Support points of `candidates` (indices into `points`) in `direction_count`
// directions of a spherical Fibonacci lattice (Gonzalez 2010, "Measurement of
// areas on a sphere using Fibonacci and latitude-longitude lattices"): the
// i-th direction has z = 1 - (2i + 1)/N and azimuth i * golden angle, which
// spreads N directions almost evenly. Returns the distinct supports, sorted.
// The candidates are copied into coordinate arrays and scanned once per block
// of directions, which keeps this O(N * directions) pass memory-friendly.
std::vector<int> LatticeSupports(const std::vector<Vec3>& points,
                                 const std::vector<int>& candidates, int direction_count) {
  constexpr int kBlock = 4;
  const double golden_angle = physics::kPi * (3.0 - std::sqrt(5.0));
  const size_t count = candidates.size();
  std::vector<double> xs(count);
  std::vector<double> ys(count);
  std::vector<double> zs(count);
  for (size_t i = 0; i < count; ++i) {
    xs[i] = points[candidates[i]].x();
    ys[i] = points[candidates[i]].y();
    zs[i] = points[candidates[i]].z();
  }
  std::vector<int> supports;
  supports.reserve(direction_count);
  for (int first = 0; first < direction_count; first += kBlock) {
    double dx[kBlock];
    double dy[kBlock];
    double dz[kBlock];
    for (int b = 0; b < kBlock; ++b) {
      // Directions past the end repeat the last one; their supports are dropped.
      const int i = std::min(first + b, direction_count - 1);
      const double z = 1.0 - (2.0 * i + 1.0) / direction_count;
      const double radius = std::sqrt(std::max(0.0, 1.0 - z * z));
      dx[b] = radius * std::cos(golden_angle * i);
      dy[b] = radius * std::sin(golden_angle * i);
      dz[b] = z;
    }
    double best_height[kBlock];
    size_t best[kBlock];
    for (int b = 0; b < kBlock; ++b) {
      best_height[b] = -std::numeric_limits<double>::infinity();
      best[b] = 0;
    }
    for (size_t i = 0; i < count; ++i) {
      for (int b = 0; b < kBlock; ++b) {
        const double height = dx[b] * xs[i] + dy[b] * ys[i] + dz[b] * zs[i];
        if (height > best_height[b]) {
          best_height[b] = height;
          best[b] = i;
        }
      }
    }
    for (int b = 0; b < kBlock && first + b < direction_count; ++b) {
      supports.push_back(candidates[best[b]]);
    }
  }
  std::sort(supports.begin(), supports.end());
  supports.erase(std::unique(supports.begin(), supports.end()), supports.end());
  return supports;
}

// Grows a Fibonacci lattice until its distinct supports just fit in
// `max_vertices`: N directions give at most N supports, so N = max_vertices
// always fits; when directions share supports (flat regions) N grows by
// doubling, then bisection.
std::vector<int> GrownLatticeSupports(const std::vector<Vec3>& points,
                                      const std::vector<int>& candidates, int max_vertices) {
  constexpr int kMaxGrowth = 16;
  constexpr int kBisections = 6;
  int fitting = max_vertices;
  std::vector<int> best = LatticeSupports(points, candidates, fitting);
  if (static_cast<int>(best.size()) == max_vertices) return best;
  int too_many = -1;
  for (int count = 2 * max_vertices; count <= kMaxGrowth * max_vertices; count *= 2) {
    std::vector<int> supports = LatticeSupports(points, candidates, count);
    if (static_cast<int>(supports.size()) > max_vertices) {
      too_many = count;
      break;
    }
    fitting = count;
    best = std::move(supports);
  }
  for (int step = 0; step < kBisections && too_many > fitting + 1; ++step) {
    const int middle = fitting + (too_many - fitting) / 2;
    std::vector<int> supports = LatticeSupports(points, candidates, middle);
    if (static_cast<int>(supports.size()) > max_vertices) {
      too_many = middle;
    } else {
      fitting = middle;
      best = std::move(supports);
    }
  }
  return best;
}

// Builds the polyhedron of a qhull result; its vertices are copies of input
// points. The polyhedron must also build again from its own faces, as the
// node builds it from the mesh helper's reply: merging and dropping
// collinear vertices change the faces whose areas and planes are checked,
// and a hull spanning 1e38 m passed the first build and failed the second
// (mesh_parser_fuzzer).
Result<ConvexPolyhedron> ToPolyhedron(const std::vector<Vec3>& points, const RawHull& hull) {
  std::vector<int> compact_index(points.size(), -1);
  std::vector<Vec3> vertices;
  vertices.reserve(hull.vertex_ids.size());
  std::vector<std::vector<int>> faces = hull.faces;
  for (std::vector<int>& face : faces) {
    for (int& id : face) {
      if (compact_index[id] < 0) {
        compact_index[id] = static_cast<int>(vertices.size());
        vertices.push_back(points[id]);
      }
      id = compact_index[id];
    }
  }
  Result<ConvexPolyhedron> polyhedron = physics::MakeConvexPolyhedron(vertices, faces);
  if (!polyhedron.ok()) {
    return Result<ConvexPolyhedron>::Error("convex hull is not a valid polyhedron: " +
                                           polyhedron.message());
  }
  std::vector<std::vector<int>> own_faces;
  own_faces.reserve(polyhedron->faces.size());
  for (int face = 0; face < static_cast<int>(polyhedron->faces.size()); ++face) {
    own_faces.push_back(polyhedron->FaceVertices(face));
  }
  const Result<ConvexPolyhedron> rebuilt =
      physics::MakeConvexPolyhedron(polyhedron->vertices, own_faces);
  if (!rebuilt.ok()) {
    return Result<ConvexPolyhedron>::Error(
        "convex hull is not a valid polyhedron once its faces are merged: " + rebuilt.message());
  }
  return polyhedron;
}

// qhull's hull of the points selected by `ids`, as a polyhedron. qhull's
// default merges only facets coplanar within round-off, so a dense, nearly
// flat patch (a terrain-like sheet, a plate with a bump) can leave two
// facets at an angle of 1e-4 rad, and a vertex on only those two that is
// off their common edge by more than the polyhedron's plane tolerance. Such
// a hull is retried with qhull's centrum pre-merge 'C-r' (qhull manual,
// "Imprecision in Qhull": a facet whose centrum is within r of a
// neighbour's hyperplane is merged into it), r growing from 1e-8 to 1e-6 of
// the points' bounding-box diagonal: each hull vertex is still an input
// point, and the merged facets are planar within the polyhedron's
// tolerance.
Result<ConvexPolyhedron> HullOf(const std::vector<Vec3>& points, const std::vector<int>& ids) {
  const Result<RawHull> hull = RunQhull(points, ids);
  if (!hull.ok()) return hull.status();
  Result<ConvexPolyhedron> polyhedron = ToPolyhedron(points, *hull);
  if (polyhedron.ok()) return polyhedron;
  const auto [low, high] = BoundsOf(points, ids);
  const double diagonal = (high - low).norm();
  for (const double relative_radius : {1e-8, 1e-7, 1e-6}) {
    char options[64];
    std::snprintf(options, sizeof(options), "qhull C-%.17g", relative_radius * diagonal);
    const Result<RawHull> merged = RunQhull(points, ids, options);
    if (!merged.ok()) continue;
    Result<ConvexPolyhedron> retried = ToPolyhedron(points, *merged);
    if (retried.ok()) return retried;
  }
  return polyhedron;
}

std::vector<int> Iota(size_t count) {
  std::vector<int> ids(count);
  for (size_t i = 0; i < count; ++i) ids[i] = static_cast<int>(i);
  return ids;
}

}  // namespace

// With more input points than max_vertices the lattice supports S are taken
// from the input directly: a support point of a finite set in a generic
// direction is a vertex of its hull, so S holds the same points as when taken
// from the hull vertices. When S fills the budget, hull(S) is the answer
// without hulling all points: if every point lies inside hull(S) it is the
// exact hull; otherwise the full hull has a vertex outside S, so more than
// max_vertices vertices, and hull(S) is its simplification. Only when S falls
// short of the budget is the full hull computed, to count its vertices, and
// the lattice grown over them.
Result<ConvexPolyhedron> ComputeConvexHull(const std::vector<Vec3>& points,
                                           const HullOptions& options) {
  if (options.max_vertices < 4) {
    return Result<ConvexPolyhedron>::Error("hull option max_vertices must be at least 4, got " +
                                           std::to_string(options.max_vertices));
  }
  if (!(options.degenerate_tolerance >= 0.0) || !std::isfinite(options.degenerate_tolerance)) {
    return Result<ConvexPolyhedron>::Error(
        "hull option degenerate_tolerance must be finite and non-negative");
  }
  const physics::Status input_status = CheckNotDegenerate(points, options.degenerate_tolerance);
  if (!input_status.ok()) return input_status;

  const std::vector<int> all_ids = Iota(points.size());
  if (static_cast<int>(points.size()) <= options.max_vertices) return HullOf(points, all_ids);

  const std::vector<int> supports = LatticeSupports(points, all_ids, options.max_vertices);
  if (static_cast<int>(supports.size()) == options.max_vertices) return HullOf(points, supports);
  const Result<RawHull> full = RunQhull(points, all_ids);
  if (!full.ok()) return full.status();
  if (static_cast<int>(full->vertex_ids.size()) <= options.max_vertices) {
    return HullOf(points, full->vertex_ids);
  }
  const Result<ConvexPolyhedron> simplified =
      HullOf(points, GrownLatticeSupports(points, full->vertex_ids, options.max_vertices));
  if (!simplified.ok()) {
    return Result<ConvexPolyhedron>::Error("simplified hull: " + simplified.message());
  }
  return simplified;
}

}  // namespace rigid_body_sim::io
