#include "rigid_body_sim/io/convex_decomposition.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "io/voxel_grid.h"

namespace rigid_body_sim::io {
namespace {

using physics::ConvexPolyhedron;
using physics::FormatNumber;
using physics::Result;
using physics::Status;
using physics::TriangleMesh;
using physics::Vec3;

// Cut planes tried per axis in the coarse search; then layers about the best
// one, at half the distance each round (V-HACD's coarse-to-fine plane
// search, Game Engine Gems 3, ch. 11, with a bisection for its fine pass).
constexpr int kCoarsePlanes = 12;
// Points at most in the hulls that rank candidate planes.
constexpr std::size_t kSearchPoints = 256;
// The grid's voxels at most when thin walls refine it (the voxel_count
// option's own upper bound).
constexpr double kMaxGridVoxels = 4e6;
// Far voxels at most that a rough evaluation tests, and that a full one
// estimates its count from.
constexpr std::size_t kSearchFar = 16384;
constexpr std::size_t kEstimateFar = 65536;
// Weight of the far volume a candidate cut's halves still cover, in the
// energy of a piece that covers far voxels: above the concavity's own weight
// (which counts that volume once), so such a piece is cut to open the
// cavity first.
constexpr double kBridgeWeight = 10.0;
// Counts every far voxel in a hull.
constexpr int kAll = std::numeric_limits<int>::max();

// The volume of a convex polyhedron by the divergence theorem with F = x / 3:
// V = (1/3) sum over faces of offset * area, each face's area from its
// polygon's fan, without triangulating it into a mesh.
double HullVolume(const ConvexPolyhedron& hull) {
  double volume = 0.0;
  for (int f = 0; f < static_cast<int>(hull.faces.size()); ++f) {
    const std::vector<int> loop = hull.FaceVertices(f);
    Vec3 twice_area = Vec3::Zero();
    for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
      twice_area += (hull.vertices[loop[i]] - hull.vertices[loop[0]])
                        .cross(hull.vertices[loop[i + 1]] - hull.vertices[loop[0]]);
    }
    volume += hull.faces[f].offset * hull.faces[f].normal.dot(twice_area) / 6.0;
  }
  return volume;
}

// Sutherland-Hodgman clipping of a planar polygon to the half-space
// side * (x[axis] - value) >= 0 (Sutherland, Hodgman, "Reentrant Polygon
// Clipping", CACM 1974).
void ClipToHalfSpace(const std::vector<Vec3>& polygon, int axis, double value, double side,
                     std::vector<Vec3>* clipped) {
  clipped->clear();
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& current = polygon[i];
    const Vec3& next = polygon[(i + 1) % n];
    const double d_current = side * (current[axis] - value);
    const double d_next = side * (next[axis] - value);
    if (d_current >= 0.0) clipped->push_back(current);
    if ((d_current >= 0.0) != (d_next >= 0.0)) {
      Vec3 crossing = current + (d_current / (d_current - d_next)) * (next - current);
      crossing[axis] = value;
      clipped->push_back(crossing);
    }
  }
}

// The decomposition's inputs and the per-mesh data every cut reuses.
class Decomposer {
 public:
  struct Piece {
    VoxelCell cell;
    std::optional<ConvexPolyhedron> hull;  // none when the part is flat
    double volume = 0.0;                   // m^3, of the mesh inside the cell
    double hull_volume = 0.0;              // m^3
    double concavity = 0.0;                // m^3, hull_volume - volume, >= 0
    int bridged = 0;                       // far voxels inside the hull
    bool final = false;                    // no cut divides its voxels
  };

  Decomposer(const TriangleMesh& mesh, const DecompositionOptions& options, double volume)
      : mesh_(mesh),
        options_(options),
        volume_(volume),
        orientation_(Orientation(mesh)),
        thickness_(WallThickness(mesh, orientation_)),
        grid_(mesh, GridVoxels(mesh, options.voxel_count, thickness_)) {
    for (const Eigen::Vector3i& triangle : mesh.triangles) {
      const Vec3& a = mesh.vertices[triangle[0]];
      const Vec3& b = mesh.vertices[triangle[1]];
      const Vec3& c = mesh.vertices[triangle[2]];
      bounds_.push_back({a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c)});
      all_triangles_.push_back(static_cast<int>(all_triangles_.size()));
    }
    // The surface lies within half a voxel diagonal, s sqrt(3) / 2, of an
    // occupied voxel's centre, so a centre farther than one wall thickness T
    // from the mesh is farther than T - s sqrt(3) / 2 from every occupied
    // centre: those are marked far.
    const double s = grid_.size();
    if (thickness_ > 0.0) grid_.MarkFar(std::max(thickness_ - 0.5 * std::sqrt(3.0) * s, 0.5 * s));
    far_stride_ = std::max<int>(1, static_cast<int>(grid_.FarCount() / kSearchFar));
    full_stride_ = std::max<int>(1, static_cast<int>(grid_.FarCount() / kEstimateFar));
  }

  // How a cut is ranked by the cavity its two halves still cover: by their
  // sum, or by their sum plus half the larger. The first leaves as little
  // covered as one cut can; the second also splits what is covered into
  // halves, which a ring (whose every single cut leaves its cavity covered)
  // needs before a second cut can open it. Neither wins on every part.
  enum class CavityRule { kSum, kSumAndLarger };

  // Cuts the piece that covers the most far voxels while the pieces number
  // under kMaxCavityPieces, then the most concave one while they number
  // under max_pieces; merges last. The cavity goes first: concavity cuts
  // made before it would spend the budget on slabs that each span it.
  std::vector<Piece> Run(CavityRule rule) {
    cavity_rule_ = rule;
    std::vector<Piece> pieces = {Evaluate(grid_.Whole(), all_triangles_)};
    const double most = options_.max_concavity * volume_;
    const auto worst_by = [&pieces](auto measure, double above) {
      int worst = -1;
      for (int i = 0; i < static_cast<int>(pieces.size()); ++i) {
        if (!pieces[i].final && measure(pieces[i]) > above &&
            (worst < 0 || measure(pieces[i]) > measure(pieces[worst]))) {
          worst = i;
        }
      }
      return worst;
    };
    for (;;) {
      const int count = static_cast<int>(pieces.size());
      int worst = -1;
      if (count < kMaxCavityPieces) {
        worst = worst_by([](const Piece& piece) { return double(piece.bridged); }, 0.0);
      }
      if (worst < 0 && count < options_.max_pieces) {
        worst = worst_by([](const Piece& piece) { return piece.concavity; }, most);
      }
      if (worst < 0) break;
      std::optional<std::pair<Piece, Piece>> halves = BestCut(pieces[worst]);
      if (!halves) {
        pieces[worst].final = true;
        continue;
      }
      pieces[worst] = std::move(halves->first);
      pieces.push_back(std::move(halves->second));
    }
    Merge(&pieces);
    return pieces;
  }

 private:
  double CavityTerm(int left, int right) const {
    const double sum = double(left) + right;
    return cavity_rule_ == CavityRule::kSum ? sum : sum + 0.5 * std::max(left, right);
  }

  // +1 for a mesh wound outward (positive signed volume), else -1.
  static double Orientation(const TriangleMesh& mesh) {
    double six_volume = 0.0;
    for (const Eigen::Vector3i& t : mesh.triangles) {
      six_volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
    }
    return six_volume < 0.0 ? -1.0 : 1.0;
  }

  // Voxels enough for an edge of at most the wall thickness / 2.5, so a
  // wall spans at least 2.5 voxels, and at least `voxel_count`; at most
  // kMaxGridVoxels.
  static int GridVoxels(const TriangleMesh& mesh, int voxel_count, double thickness) {
    if (!(thickness > 0.0)) return voxel_count;
    const auto [lower, upper] = MeshBounds(mesh);
    const Vec3 cells = (upper - lower) / (thickness / 2.5);
    const double needed = std::max(cells.prod(), cells.maxCoeff() * cells.maxCoeff());
    return static_cast<int>(std::clamp(needed, double(voxel_count), double(kMaxGridVoxels)));
  }

 private:
  // The mesh's volume inside the box [lower, upper], exact, signed by the
  // mesh's orientation. Divergence theorem with F = (0, 0, clamp(z) - z_low):
  // along each vertical line the inside length within the box is the sum
  // over surface crossings of +-(clamp(z, z_low, z_high) - z_low), exits
  // (upward-facing triangles) counting +, entries -. So each triangle,
  // clipped to the box's x and y range, contributes its signed xy-area times
  // that clamped height: split at z_low and z_high, the middle part by its
  // mean height, the part above by the box's height.
  double SignedVolume(const Vec3& lower, const Vec3& upper,
                      const std::vector<int>& triangles) const {
    double volume = 0.0;
    std::vector<Vec3> polygon;
    std::vector<Vec3> scratch;
    std::vector<Vec3> middle;
    for (const int t : triangles) {
      const auto& [low, high] = bounds_[t];
      if ((high.head<2>().array() < lower.head<2>().array()).any() ||
          (low.head<2>().array() > upper.head<2>().array()).any() || high.z() < lower.z()) {
        continue;
      }
      ClipTriangle(t, lower, upper, /*axes=*/2, &polygon, &scratch);
      if (polygon.size() < 3) continue;
      ClipToHalfSpace(polygon, 2, upper.z(), 1.0, &scratch);
      volume += (upper.z() - lower.z()) * FanArea(scratch);
      ClipToHalfSpace(polygon, 2, upper.z(), -1.0, &scratch);
      ClipToHalfSpace(scratch, 2, lower.z(), 1.0, &middle);
      for (std::size_t i = 1; i + 1 < middle.size(); ++i) {
        const double area = XyArea(middle[0], middle[i], middle[i + 1]);
        volume += area * ((middle[0].z() + middle[i].z() + middle[i + 1].z()) / 3.0 - lower.z());
      }
    }
    return volume;
  }

  static double XyArea(const Vec3& a, const Vec3& b, const Vec3& c) {
    return 0.5 * ((b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x()));
  }
  static double FanArea(const std::vector<Vec3>& polygon) {
    double area = 0.0;
    for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
      area += XyArea(polygon[0], polygon[i], polygon[i + 1]);
    }
    return area;
  }

  // Triangle t clipped to the box on its first `axes` axes.
  void ClipTriangle(std::size_t t, const Vec3& lower, const Vec3& upper, int axes,
                    std::vector<Vec3>* polygon, std::vector<Vec3>* scratch) const {
    const Eigen::Vector3i& triangle = mesh_.triangles[t];
    polygon->assign(
        {mesh_.vertices[triangle[0]], mesh_.vertices[triangle[1]], mesh_.vertices[triangle[2]]});
    for (int axis = 0; axis < axes && polygon->size() >= 3; ++axis) {
      ClipToHalfSpace(*polygon, axis, lower[axis], 1.0, scratch);
      ClipToHalfSpace(*scratch, axis, upper[axis], -1.0, polygon);
    }
  }

  // The triangles that can matter to a cell or any cell inside it: those
  // over its xy-rectangle that reach above its floor (the volume integral
  // and the inside test look up the column).
  std::vector<int> ColumnTriangles(const VoxelCell& cell) const {
    const Vec3 lower = grid_.Corner(cell.lower);
    const Vec3 upper = grid_.Corner(cell.upper);
    std::vector<int> triangles;
    for (const int t : all_triangles_) {
      const auto& [low, high] = bounds_[t];
      if ((high.head<2>().array() >= lower.head<2>().array()).all() &&
          (low.head<2>().array() <= upper.head<2>().array()).all() && high.z() >= lower.z()) {
        triangles.push_back(t);
      }
    }
    return triangles;
  }

  // Vertical-ray parity, as in the voxel fill.
  bool Inside(const Vec3& point, const std::vector<int>& triangles) const {
    const Vec3 from = point + grid_.nudge();
    int crossings = 0;
    for (const int t : triangles) {
      const auto& [low, high] = bounds_[t];
      if (high.z() < from.z() || from.x() < low.x() || from.x() > high.x() || from.y() < low.y() ||
          from.y() > high.y()) {
        continue;
      }
      const Eigen::Vector3i& tri = mesh_.triangles[t];
      const auto z = VerticalCrossing(mesh_.vertices[tri[0]], mesh_.vertices[tri[1]],
                                      mesh_.vertices[tri[2]], from.x(), from.y());
      if (z && *z > from.z()) ++crossings;
    }
    return crossings % 2 == 1;
  }

  // The part of the mesh in a cell, its exact volume and the hull of its
  // extreme points: the mesh's triangles clipped to the cell, and the
  // cell's corners that lie inside the mesh. A `rough` evaluation, for the
  // plane search, hulls at most kSearchPoints of them, evenly strided (the
  // paper's downsampled hulls): its concavity ranks planes, the chosen cut's
  // pieces are evaluated in full.
  Piece Evaluate(const VoxelCell& cell, const std::vector<int>& triangles,
                 bool rough = false) const {
    Piece piece;
    piece.cell = cell;
    const Vec3 lower = grid_.Corner(cell.lower);
    const Vec3 upper = grid_.Corner(cell.upper);
    std::vector<Vec3> points;
    std::vector<Vec3> polygon;
    std::vector<Vec3> scratch;
    // A vertex shared by triangles inside the cell is taken once: the hull's
    // cost grows with its input.
    ++stamp_;
    for (const int t : triangles) {
      const auto& [low, high] = bounds_[t];
      if ((high.array() < lower.array()).any() || (low.array() > upper.array()).any()) continue;
      if ((low.array() >= lower.array()).all() && (high.array() <= upper.array()).all()) {
        for (int k = 0; k < 3; ++k) {
          const int vertex = mesh_.triangles[t][k];
          if (stamps_[vertex] == stamp_) continue;
          stamps_[vertex] = stamp_;
          points.push_back(mesh_.vertices[vertex]);
        }
        continue;
      }
      ClipTriangle(t, lower, upper, 3, &polygon, &scratch);
      points.insert(points.end(), polygon.begin(), polygon.end());
    }
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 point((corner & 1) ? upper.x() : lower.x(), (corner & 2) ? upper.y() : lower.y(),
                       (corner & 4) ? upper.z() : lower.z());
      if (Inside(point, triangles)) points.push_back(point);
    }
    piece.volume = orientation_ * SignedVolume(lower, upper, triangles);
    HullOptions hull_options = options_.hull;
    Result<ConvexPolyhedron> hull = Result<ConvexPolyhedron>::Error("");
    if (rough && points.size() > kSearchPoints) {
      const std::size_t stride = (points.size() + kSearchPoints - 1) / kSearchPoints;
      std::vector<Vec3> sample;
      for (std::size_t i = 0; i < points.size(); i += stride) sample.push_back(points[i]);
      hull_options.max_vertices = static_cast<int>(kSearchPoints);
      hull = ComputeConvexHull(sample, hull_options);
    }
    // A sample can be flat where the part is not (a slab one voxel thick):
    // then the part's own points decide, or a flat sample would rank the
    // cut that makes it as free of concavity.
    if (!hull.ok()) hull = ComputeConvexHull(points, hull_options);
    if (hull.ok()) {
      piece.hull_volume = HullVolume(*hull);
      piece.hull = std::move(hull).value();
      piece.concavity = std::max(0.0, piece.hull_volume - piece.volume);
      // Full evaluations estimate from more far voxels, and look at every
      // one when the estimate is none, so a piece that covers any is cut.
      piece.bridged = grid_.FarInside(*piece.hull, cell, kAll, rough ? far_stride_ : full_stride_);
      if (!rough && piece.bridged == 0) piece.bridged = grid_.FarInside(*piece.hull, cell, 1);
    }
    return piece;
  }

  // The cut of V-HACD's energy E = (C_left + C_right) / V + alpha |V_left -
  // V_right| / V over axis-aligned planes on voxel layers, both sides
  // holding voxels; none when no plane divides the piece's voxels.
  std::optional<std::pair<Piece, Piece>> BestCut(const Piece& piece) const {
    const VoxelCell occupied = grid_.Occupied(piece.cell);
    const std::vector<int> triangles = ColumnTriangles(piece.cell);
    const double voxel_volume = std::pow(grid_.size(), 3);
    std::optional<std::pair<Piece, Piece>> best;
    double best_energy = std::numeric_limits<double>::infinity();
    int best_axis = -1;
    int best_layer = -1;
    const auto try_cut = [&](int axis, int layer) {
      VoxelCell left = piece.cell;
      VoxelCell right = piece.cell;
      left.upper[axis] = layer;
      right.lower[axis] = layer;
      const int left_voxels = grid_.Count(left);
      const int right_voxels = grid_.Count(right);
      if (left_voxels == 0 || right_voxels == 0) return;
      Piece l = Evaluate(left, triangles, /*rough=*/true);
      Piece r = Evaluate(right, triangles, /*rough=*/true);
      const double energy =
          (l.concavity + r.concavity) / volume_ +
          options_.balance_weight * voxel_volume * std::abs(left_voxels - right_voxels) / volume_ +
          (piece.bridged > 0
               ? kBridgeWeight * voxel_volume * CavityTerm(l.bridged, r.bridged) / volume_
               : 0.0);
      if (energy < best_energy) {
        best_energy = energy;
        best_axis = axis;
        best_layer = layer;
        best = std::make_pair(std::move(l), std::move(r));
      }
    };
    int steps[3] = {1, 1, 1};
    for (int axis = 0; axis < 3; ++axis) {
      const int span = occupied.upper[axis] - occupied.lower[axis];
      steps[axis] = std::max(1, span / kCoarsePlanes);
      for (int layer = occupied.lower[axis] + steps[axis]; layer < occupied.upper[axis];
           layer += steps[axis]) {
        try_cut(axis, layer);
      }
    }
    // Then about the best plane on its axis, the interval halved each round.
    if (best_axis >= 0) {
      const int axis = best_axis;
      for (int step = steps[axis]; step > 1;) {
        step = (step + 1) / 2;
        const int centre = best_layer;
        for (const int layer : {centre - step, centre + step}) {
          if (layer > occupied.lower[axis] && layer < occupied.upper[axis]) try_cut(axis, layer);
        }
      }
    }
    if (!best) return best;
    return std::make_pair(Evaluate(best->first.cell, triangles),
                          Evaluate(best->second.cell, triangles));
  }

  // The volume the hull of two pieces adds to their own hulls, and that
  // hull; none when they do not touch or either is flat.
  std::optional<std::pair<double, ConvexPolyhedron>> JointHull(const Piece& a,
                                                               const Piece& b) const {
    if (!a.hull || !b.hull || (a.cell.lower > b.cell.upper).any() ||
        (b.cell.lower > a.cell.upper).any()) {
      return std::nullopt;
    }
    std::vector<Vec3> points = a.hull->vertices;
    points.insert(points.end(), b.hull->vertices.begin(), b.hull->vertices.end());
    Result<ConvexPolyhedron> hull = ComputeConvexHull(points, options_.hull);
    if (!hull.ok()) return std::nullopt;
    const double added = HullVolume(*hull) - a.hull_volume - b.hull_volume;
    return std::make_pair(added, std::move(hull).value());
  }

  // Greedy merging (V-HACD's last stage): the touching pair whose joint hull
  // adds the least volume merges while that volume is below merge_volume of
  // the mesh and the merged piece stays within max_concavity.
  void Merge(std::vector<Piece>* pieces) const {
    const double inf = std::numeric_limits<double>::infinity();
    const auto cost = [&](const Piece& a, const Piece& b) {
      const auto joint = JointHull(a, b);
      if (!joint || a.concavity + b.concavity + joint->first > options_.max_concavity * volume_) {
        return inf;
      }
      VoxelCell both{a.cell.lower.min(b.cell.lower), a.cell.upper.max(b.cell.upper)};
      if (grid_.FarInside(joint->second, both, 1) > 0) return inf;
      return joint->first;
    };
    std::vector<std::vector<double>> costs(pieces->size(),
                                           std::vector<double>(pieces->size(), inf));
    for (std::size_t i = 0; i < pieces->size(); ++i) {
      for (std::size_t j = i + 1; j < pieces->size(); ++j)
        costs[i][j] = cost((*pieces)[i], (*pieces)[j]);
    }
    for (;;) {
      std::size_t best_i = 0;
      std::size_t best_j = 0;
      double best = inf;
      for (std::size_t i = 0; i < pieces->size(); ++i) {
        for (std::size_t j = i + 1; j < pieces->size(); ++j) {
          if (costs[i][j] < best) {
            best = costs[i][j];
            best_i = i;
            best_j = j;
          }
        }
      }
      if (!(best <= options_.merge_volume * volume_)) return;
      Piece& kept = (*pieces)[best_i];
      const Piece& gone = (*pieces)[best_j];
      auto joint = JointHull(kept, gone);
      kept.concavity += gone.concavity + joint->first;
      kept.volume += gone.volume;
      kept.hull_volume = kept.volume + kept.concavity;
      kept.hull = std::move(joint->second);
      kept.cell.lower = kept.cell.lower.min(gone.cell.lower);
      kept.cell.upper = kept.cell.upper.max(gone.cell.upper);
      pieces->erase(pieces->begin() + static_cast<std::ptrdiff_t>(best_j));
      costs.erase(costs.begin() + static_cast<std::ptrdiff_t>(best_j));
      for (std::vector<double>& row : costs)
        row.erase(row.begin() + static_cast<std::ptrdiff_t>(best_j));
      for (std::size_t k = 0; k < pieces->size(); ++k) {
        if (k == best_i) continue;
        const double c = cost(kept, (*pieces)[k]);
        costs[std::min(k, best_i)][std::max(k, best_i)] = c;
      }
    }
  }

  const TriangleMesh& mesh_;
  const DecompositionOptions& options_;
  double volume_;       // m^3, the mesh's
  double orientation_;  // -1 for a mesh wound inside out
  double thickness_;    // m, WallThickness; 0 when unknown
  VoxelGrid grid_;
  CavityRule cavity_rule_ = CavityRule::kSum;
  int full_stride_ = 1;                        // of the far voxels a full evaluation estimates from
  int far_stride_ = 1;                         // of the far voxels a rough evaluation tests
  std::vector<std::pair<Vec3, Vec3>> bounds_;  // per triangle
  std::vector<int> all_triangles_;             // 0, 1, ..., triangle count - 1
  // Per vertex, the last Evaluate that took it.
  mutable std::vector<long> stamps_ = std::vector<long>(mesh_.vertices.size(), 0);
  mutable long stamp_ = 0;
};

Status CheckRange(const std::string& field, double value, double low, double high, bool open_low) {
  const bool above_low = open_low ? value > low : value >= low;
  if (above_low && value <= high) return Status::Ok();
  return Status::Error("decomposition option " + field + " " + FormatNumber(value) +
                       " is outside " + (open_low ? "(" : "[") + FormatNumber(low) + ", " +
                       FormatNumber(high) + "]");
}

}  // namespace

Status CheckDecompositionOptions(const DecompositionOptions& options) {
  for (const Status& status :
       {CheckRange("voxel_count", options.voxel_count, 1000, 4e6, false),
        CheckRange("max_pieces", options.max_pieces, 1, 64, false),
        CheckRange("max_concavity", options.max_concavity, 0.0, 1.0, true),
        CheckRange("balance_weight", options.balance_weight, 0.0, 1.0, false),
        CheckRange("merge_volume", options.merge_volume, 0.0, 0.999, false),
        CheckRange("convex_ratio", options.convex_ratio, 0.0, 1.0, true)}) {
    if (!status.ok()) return status;
  }
  return Status::Ok();
}

Result<std::vector<ConvexPolyhedron>> DecomposeConvex(const TriangleMesh& mesh,
                                                      const DecompositionOptions& options) {
  using Out = Result<std::vector<ConvexPolyhedron>>;
  if (Status status = CheckDecompositionOptions(options); !status.ok()) return status;
  // Closed, finite, indices in range and of positive volume, or a message.
  Result<physics::MassProperties> mass = physics::TriangleMeshMassProperties(1.0, mesh);
  if (!mass.ok()) return Out::Error("convex decomposition needs a closed mesh: " + mass.message());
  // The second rule runs only when the first leaves a cavity covered, and
  // the pieces that cover the least (then the fewer) are kept.
  Decomposer decomposer(mesh, options, mass->mass);
  std::vector<Decomposer::Piece> pieces = decomposer.Run(Decomposer::CavityRule::kSum);
  const auto covered = [](const std::vector<Decomposer::Piece>& list) {
    long total = 0;
    for (const Decomposer::Piece& piece : list) total += piece.bridged;
    return total;
  };
  if (covered(pieces) > 0) {
    std::vector<Decomposer::Piece> other = decomposer.Run(Decomposer::CavityRule::kSumAndLarger);
    if (covered(other) < covered(pieces) ||
        (covered(other) == covered(pieces) && other.size() < pieces.size())) {
      pieces = std::move(other);
    }
  }
  std::vector<ConvexPolyhedron> hulls;
  for (Decomposer::Piece& piece : pieces) {
    if (piece.hull) hulls.push_back(std::move(*piece.hull));
  }
  if (hulls.empty()) return Out::Error("convex decomposition found no piece of positive volume");
  return hulls;
}

Result<std::vector<ConvexPolyhedron>> ConvexPieces(const TriangleMesh& mesh,
                                                   const DecompositionOptions& options,
                                                   PiecesRule rule) {
  if (Status status = CheckDecompositionOptions(options); !status.ok()) return status;
  if (rule == PiecesRule::kAuto) {
    Result<ConvexPolyhedron> hull = ComputeConvexHull(mesh.vertices, options.hull);
    if (!hull.ok()) return hull.status();
    Result<physics::MassProperties> mass = physics::TriangleMeshMassProperties(1.0, mesh);
    const double hull_volume = HullVolume(*hull);
    // An open mesh bounds no volume: its hull is all there is to collide.
    if (!mass.ok() || mass->mass >= options.convex_ratio * hull_volume ||
        mesh.triangles.size() > kMaxAutoTriangles) {
      std::vector<ConvexPolyhedron> one;
      one.push_back(std::move(hull).value());
      return one;
    }
  }
  return DecomposeConvex(mesh, options);
}

}  // namespace rigid_body_sim::io
