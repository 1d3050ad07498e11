// The voxels of a closed triangle mesh for the convex decomposition: which
// voxel centres lie inside it (counted over any box of voxels in constant
// time), which voxels its surface or interior occupies, and the empty voxels
// far from both, the ones a piece must not take into its hull. Also the
// mesh's wall thickness, which sets the grid's resolution and how far from
// the walls a cavity must stay open. ROS-free; runs in the mesh helper.
#ifndef RIGID_BODY_SIM_IO_VOXEL_GRID_H_
#define RIGID_BODY_SIM_IO_VOXEL_GRID_H_

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

using Index3 = Eigen::Array3i;

// The height at which the vertical line through (x, y) crosses triangle
// abc, when it crosses its interior. Barycentric coordinates of the xy
// projection; a line through an edge or a vertex, or a vertical triangle,
// is no crossing (callers nudge their lines off the grid's symmetries).
std::optional<double> VerticalCrossing(const physics::Vec3& a, const physics::Vec3& b,
                                       const physics::Vec3& c, double x, double y);

// Voxels [lower, upper) per axis: a box of the grid.
struct VoxelCell {
  Index3 lower = Index3::Zero();
  Index3 upper = Index3::Zero();
};

// Cubic voxels over the mesh's bounding box, centred on it.
class VoxelGrid {
 public:
  // About `voxel_count` voxels (a flat mesh keeps at most sqrt(count)
  // layers per axis).
  VoxelGrid(const physics::TriangleMesh& mesh, int voxel_count);

  double size() const { return size_; }  // m, the voxels' edge
  const physics::Vec3& nudge() const { return nudge_; }
  VoxelCell Whole() const { return VoxelCell{Index3::Zero(), cells_}; }
  physics::Vec3 Corner(const Index3& index) const {
    return origin_ + size_ * index.cast<double>().matrix();
  }

  // Voxel centres inside the mesh within the cell.
  int Count(const VoxelCell& cell) const;
  // The smallest cell inside `cell` that holds all of its inside voxels.
  VoxelCell Occupied(const VoxelCell& cell) const;

  // Marks as far the centres of the voxels that neither the surface nor the
  // interior occupies and whose centre is farther than `gap` (m) from every
  // occupied voxel's centre.
  void MarkFar(double gap);
  // How many far centres inside `cell` lie inside `hull`, counting up to
  // `most`. A `stride` above 1 tests every stride-th far centre only and
  // scales the count by it, for a quick estimate.
  int FarInside(const physics::ConvexPolyhedron& hull, const VoxelCell& cell, int most,
                int stride = 1) const;
  std::size_t FarCount() const { return far_.size(); }

 private:
  int Sum(int i, int j, int k) const { return prefix_[Index(i, j, k)]; }
  std::size_t Index(int i, int j, int k) const {
    return (static_cast<std::size_t>(i) * (cells_[1] + 1) + j) * (cells_[2] + 1) + k;
  }
  std::size_t Voxel(int i, int j, int k) const {
    return (static_cast<std::size_t>(i) * cells_[1] + j) * cells_[2] + k;
  }
  void Fill(const physics::TriangleMesh& mesh);
  void MarkSurface(const physics::TriangleMesh& mesh);

  physics::Vec3 origin_ = physics::Vec3::Zero();
  physics::Vec3 nudge_ = physics::Vec3::Zero();
  double size_ = 0.0;  // m
  Index3 cells_ = Index3::Ones();
  std::vector<int> prefix_;             // inside centres, summed over i, j, k
  std::vector<std::uint8_t> occupied_;  // per voxel: the surface or the interior
  // Far voxels (their index), in order of their x layer; far_start_[i] is
  // layer i's first.
  std::vector<std::uint32_t> far_;
  std::vector<std::size_t> far_start_;
};

// The box of the mesh's vertices (m): lower and upper corners.
std::pair<physics::Vec3, physics::Vec3> MeshBounds(const physics::TriangleMesh& mesh);

// The wall thickness of a closed mesh (m): its shape diameter, the distance
// from a surface point along the inward normal to the surface's other side,
// sampled at up to 256 triangle centroids chosen evenly by area, and the
// first quartile of those distances, so a part that is mostly thin walls
// reads as its walls. `orientation` is +1 for outward-wound triangles, -1
// for inward. 0 when no sample ray finds the other side.
double WallThickness(const physics::TriangleMesh& mesh, double orientation);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_VOXEL_GRID_H_
