#include "io/voxel_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rigid_body_sim::io {
namespace {

using physics::TriangleMesh;
using physics::Vec3;

// Sample rays of WallThickness.
constexpr int kThicknessRays = 256;

// The squared Euclidean distance transform of one line of samples, in
// place: d(p) = min_q ((p - q)^2 + f(q)), by the lower envelope of the
// parabolas rooted at the finite samples (Felzenszwalb, Huttenlocher,
// "Distance Transforms of Sampled Functions", Theory of Computing 8, 2012,
// section 2.1). `roots`, `bounds` and `line` are scratch of n, n + 1 and n.
void SquaredDistanceLine(float* f, int n, std::ptrdiff_t stride, std::vector<int>* roots,
                         std::vector<double>* bounds, std::vector<float>* line) {
  const double inf = std::numeric_limits<double>::infinity();
  int* v = roots->data();
  double* z = bounds->data();
  const auto at = [&](int q) { return static_cast<double>(f[q * stride]); };
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (!std::isfinite(at(q))) continue;
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -inf;
      z[1] = inf;
      continue;
    }
    // Where parabola q overtakes the envelope's last; z[0] = -inf stops it.
    double s = 0.0;
    for (;;) {
      const int p = v[k];
      s = ((at(q) + double(q) * q) - (at(p) + double(p) * p)) / (2.0 * (q - p));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = inf;
  }
  if (k < 0) return;  // no finite sample: every distance stays infinite
  float* envelope = line->data();
  for (int q = 0, j = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    envelope[q] = static_cast<float>(double(q - v[j]) * (q - v[j]) + at(v[j]));
  }
  for (int q = 0; q < n; ++q) f[q * stride] = envelope[q];
}

// Moller-Trumbore ray-triangle intersection (Moller, Trumbore, "Fast,
// Minimum Storage Ray/Triangle Intersection", JGT 1997), either side: the
// distance along the unit `direction`, or infinity.
double RayTriangle(const Vec3& origin, const Vec3& direction, const Vec3& a, const Vec3& b,
                   const Vec3& c) {
  const double inf = std::numeric_limits<double>::infinity();
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const Vec3 p = direction.cross(ac);
  const double det = ab.dot(p);
  if (det == 0.0) return inf;
  const Vec3 s = origin - a;
  const double u = s.dot(p) / det;
  if (u < 0.0 || u > 1.0) return inf;
  const Vec3 q = s.cross(ab);
  const double v = direction.dot(q) / det;
  if (v < 0.0 || u + v > 1.0) return inf;
  return ac.dot(q) / det;
}

}  // namespace

std::optional<double> VerticalCrossing(const Vec3& a, const Vec3& b, const Vec3& c, double x,
                                       double y) {
  const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
  if (area == 0.0) return std::nullopt;
  const double w_b = ((x - a.x()) * (c.y() - a.y()) - (y - a.y()) * (c.x() - a.x())) / area;
  const double w_c = ((b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x())) / area;
  const double w_a = 1.0 - w_b - w_c;
  if (!(w_a > 0.0 && w_b > 0.0 && w_c > 0.0)) return std::nullopt;
  return w_a * a.z() + w_b * b.z() + w_c * c.z();
}

std::pair<Vec3, Vec3> MeshBounds(const TriangleMesh& mesh) {
  Vec3 lower = mesh.vertices.front();
  Vec3 upper = lower;
  for (const Vec3& vertex : mesh.vertices) {
    lower = lower.cwiseMin(vertex);
    upper = upper.cwiseMax(vertex);
  }
  return {lower, upper};
}

VoxelGrid::VoxelGrid(const TriangleMesh& mesh, int voxel_count) {
  const auto [lower, upper] = MeshBounds(mesh);
  const Vec3 extent = upper - lower;
  const double count = voxel_count;
  size_ = std::max(std::cbrt(extent.prod() / count), extent.maxCoeff() / std::sqrt(count));
  for (int k = 0; k < 3; ++k) cells_[k] = static_cast<int>(std::floor(extent[k] / size_)) + 1;
  // Centred: the grid overhangs the mesh equally on both sides, so a
  // symmetric mesh gets symmetric voxels.
  origin_ = lower - 0.5 * (cells_.cast<double>().matrix() * size_ - extent);
  nudge_ = size_ * 1e-5 * Vec3(0.7548776662, 0.5698402910, 0.0);
  Fill(mesh);
  MarkSurface(mesh);
}

int VoxelGrid::Count(const VoxelCell& cell) const {
  const Index3& l = cell.lower;
  const Index3& u = cell.upper;
  return Sum(u[0], u[1], u[2]) - Sum(l[0], u[1], u[2]) - Sum(u[0], l[1], u[2]) -
         Sum(u[0], u[1], l[2]) + Sum(l[0], l[1], u[2]) + Sum(l[0], u[1], l[2]) +
         Sum(u[0], l[1], l[2]) - Sum(l[0], l[1], l[2]);
}

VoxelCell VoxelGrid::Occupied(const VoxelCell& cell) const {
  VoxelCell tight = cell;
  for (int axis = 0; axis < 3; ++axis) {
    VoxelCell slab = tight;
    for (slab.upper[axis] = slab.lower[axis] + 1;
         tight.lower[axis] < tight.upper[axis] && Count(slab) == 0; ++slab.upper[axis]) {
      slab.lower[axis] = ++tight.lower[axis];
    }
    slab = tight;
    for (slab.lower[axis] = slab.upper[axis] - 1;
         tight.upper[axis] > tight.lower[axis] && Count(slab) == 0; --slab.lower[axis]) {
      slab.upper[axis] = --tight.upper[axis];
    }
  }
  return tight;
}

// Interior fill by ray parity: the vertical line through each column's
// centre crosses the closed surface an even number of times, and a centre is
// inside when an odd number of crossings lie below it. Then a 3-D prefix
// sum, so the voxels of any cell count in constant time.
void VoxelGrid::Fill(const TriangleMesh& mesh) {
  const int nx = cells_[0];
  const int ny = cells_[1];
  const int nz = cells_[2];
  std::vector<std::vector<double>> crossings(static_cast<std::size_t>(nx) * ny);
  const auto column = [&](double coordinate, int axis) {
    return (coordinate - origin_[axis] - nudge_[axis]) / size_ - 0.5;
  };
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    const Vec3& a = mesh.vertices[triangle[0]];
    const Vec3& b = mesh.vertices[triangle[1]];
    const Vec3& c = mesh.vertices[triangle[2]];
    const Vec3 low = a.cwiseMin(b).cwiseMin(c);
    const Vec3 high = a.cwiseMax(b).cwiseMax(c);
    const int i0 = std::max(0, static_cast<int>(std::floor(column(low.x(), 0))));
    const int i1 = std::min(nx - 1, static_cast<int>(std::ceil(column(high.x(), 0))));
    const int j0 = std::max(0, static_cast<int>(std::floor(column(low.y(), 1))));
    const int j1 = std::min(ny - 1, static_cast<int>(std::ceil(column(high.y(), 1))));
    for (int i = i0; i <= i1; ++i) {
      for (int j = j0; j <= j1; ++j) {
        const Vec3 centre = Corner(Index3(i, j, 0)) + Vec3(0.5, 0.5, 0.0) * size_ + nudge_;
        if (const auto z = VerticalCrossing(a, b, c, centre.x(), centre.y())) {
          crossings[static_cast<std::size_t>(i) * ny + j].push_back(*z);
        }
      }
    }
  }
  prefix_.assign(static_cast<std::size_t>(nx + 1) * (ny + 1) * (nz + 1), 0);
  occupied_.assign(static_cast<std::size_t>(nx) * ny * nz, 0);
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      std::vector<double>& heights = crossings[static_cast<std::size_t>(i) * ny + j];
      std::sort(heights.begin(), heights.end());
      std::size_t below = 0;
      for (int k = 0; k < nz; ++k) {
        const double z = origin_.z() + (k + 0.5) * size_;
        while (below < heights.size() && heights[below] < z) ++below;
        const int inside = below % 2 == 1 ? 1 : 0;
        prefix_[Index(i + 1, j + 1, k + 1)] = inside;
        occupied_[Voxel(i, j, k)] = static_cast<std::uint8_t>(inside);
      }
    }
  }
  for (int i = 1; i <= nx; ++i) {
    for (int j = 1; j <= ny; ++j) {
      for (int k = 1; k <= nz; ++k) {
        prefix_[Index(i, j, k)] += Sum(i - 1, j, k) + Sum(i, j - 1, k) + Sum(i, j, k - 1) -
                                   Sum(i - 1, j - 1, k) - Sum(i - 1, j, k - 1) -
                                   Sum(i, j - 1, k - 1) + Sum(i - 1, j - 1, k - 1);
      }
    }
  }
}

// Every voxel the surface passes through, so a wall thinner than a voxel
// still occupies one: each triangle sampled on a barycentric lattice finer
// than half a voxel along its longest edge.
void VoxelGrid::MarkSurface(const TriangleMesh& mesh) {
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    const Vec3& a = mesh.vertices[triangle[0]];
    const Vec3 ab = mesh.vertices[triangle[1]] - a;
    const Vec3 ac = mesh.vertices[triangle[2]] - a;
    const double longest = std::max({ab.norm(), ac.norm(), (ac - ab).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(2.0 * longest / size_)));
    for (int u = 0; u <= n; ++u) {
      for (int v = 0; u + v <= n; ++v) {
        const Vec3 point =
            a + (static_cast<double>(u) / n) * ab + (static_cast<double>(v) / n) * ac;
        Index3 index = ((point - origin_) / size_).array().floor().cast<int>();
        index = index.max(0).min(cells_ - 1);
        occupied_[Voxel(index[0], index[1], index[2])] = 1;
      }
    }
  }
}

void VoxelGrid::MarkFar(double gap) {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> distance(occupied_.size());
  for (std::size_t v = 0; v < occupied_.size(); ++v) distance[v] = occupied_[v] ? 0.0f : inf;
  const int n[3] = {cells_[0], cells_[1], cells_[2]};
  const std::ptrdiff_t strides[3] = {static_cast<std::ptrdiff_t>(n[1]) * n[2], n[2], 1};
  std::vector<int> roots(static_cast<std::size_t>(cells_.maxCoeff()));
  std::vector<double> bounds(roots.size() + 1);
  std::vector<float> scratch(roots.size());
  // Separable: one pass of lines along each axis in turn.
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3;
    const int b = (axis + 2) % 3;
    for (int i = 0; i < n[a]; ++i) {
      for (int j = 0; j < n[b]; ++j) {
        float* line = distance.data() + i * strides[a] + j * strides[b];
        SquaredDistanceLine(line, n[axis], strides[axis], &roots, &bounds, &scratch);
      }
    }
  }
  const double least = gap / size_;
  far_.clear();
  far_start_.assign(static_cast<std::size_t>(n[0]) + 1, 0);
  for (int i = 0; i < n[0]; ++i) {
    far_start_[i] = far_.size();
    for (int j = 0; j < n[1]; ++j) {
      for (int k = 0; k < n[2]; ++k) {
        if (distance[Voxel(i, j, k)] > least * least) {
          far_.push_back(static_cast<std::uint32_t>(Voxel(i, j, k)));
        }
      }
    }
  }
  far_start_[n[0]] = far_.size();
}

int VoxelGrid::FarInside(const physics::ConvexPolyhedron& hull, const VoxelCell& cell, int most,
                         int stride) const {
  if (far_start_.empty()) return 0;
  const std::size_t layer = static_cast<std::size_t>(cells_[1]) * cells_[2];
  int inside = 0;
  for (std::size_t p = far_start_[cell.lower[0]]; p < far_start_[cell.upper[0]]; p += stride) {
    const std::size_t voxel = far_[p];
    const int j = static_cast<int>(voxel % layer / cells_[2]);
    const int k = static_cast<int>(voxel % cells_[2]);
    if (j < cell.lower[1] || j >= cell.upper[1] || k < cell.lower[2] || k >= cell.upper[2]) {
      continue;
    }
    const Vec3 point =
        Corner(Index3(static_cast<int>(voxel / layer), j, k)) + Vec3::Constant(0.5 * size_);
    bool within = true;
    for (const physics::ConvexPolyhedron::Face& face : hull.faces) {
      if (face.normal.dot(point) > face.offset) {
        within = false;
        break;
      }
    }
    if (within && (inside += stride) >= most) return inside;
  }
  return inside;
}

double WallThickness(const TriangleMesh& mesh, double orientation) {
  std::vector<double> cumulative;
  double total = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    total += (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
    cumulative.push_back(total);
  }
  if (!(total > 0.0)) return 0.0;
  std::vector<double> depths;
  for (int s = 0; s < kThicknessRays; ++s) {
    const double target = (s + 0.5) / kThicknessRays * total;
    const std::size_t source = static_cast<std::size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin());
    const Eigen::Vector3i& t = mesh.triangles[std::min(source, mesh.triangles.size() - 1)];
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3& b = mesh.vertices[t[1]];
    const Vec3& c = mesh.vertices[t[2]];
    const Vec3 normal = (b - a).cross(c - a);
    if (normal.squaredNorm() == 0.0) continue;
    const Vec3 inward = -orientation * normal.normalized();
    const Vec3 centroid = (a + b + c) / 3.0;
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t other = 0; other < mesh.triangles.size(); ++other) {
      if (other == source) continue;
      const Eigen::Vector3i& o = mesh.triangles[other];
      const double d = RayTriangle(centroid, inward, mesh.vertices[o[0]], mesh.vertices[o[1]],
                                   mesh.vertices[o[2]]);
      if (d > 0.0 && d < nearest) nearest = d;
    }
    if (std::isfinite(nearest)) depths.push_back(nearest);
  }
  if (depths.empty()) return 0.0;
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 4, depths.end());
  return depths[depths.size() / 4];
}

}  // namespace rigid_body_sim::io
