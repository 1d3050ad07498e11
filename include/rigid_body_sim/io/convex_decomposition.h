// Approximate convex decomposition of a closed triangle mesh into convex
// pieces, for moving bodies whose meshes are not convex (a mug, an L-bracket).
// After V-HACD (Mamou, Lengyel, Peters, "Volumetric Hierarchical Approximate
// Convex Decomposition", Game Engine Gems 3, 2016, ch. 11): the mesh is
// voxelized with its interior filled, then cut recursively by axis-aligned
// planes: first pieces whose hulls take in empty space farther than one wall
// thickness from the mesh (a cup's cavity), until none does, then pieces
// whose hulls exceed them by much (concavity), each by the plane that
// minimises the halves' concavity, cavity and a balance term, until the
// piece budget is spent; adjacent pieces whose joint hull adds little volume
// and no such space are merged. docs/design.md
// gives the equations. ROS-free; runs in the mesh helper process on untrusted meshes.
#ifndef RIGID_BODY_SIM_IO_CONVEX_DECOMPOSITION_H_
#define RIGID_BODY_SIM_IO_CONVEX_DECOMPOSITION_H_

#include <cstddef>
#include <vector>

#include "rigid_body_sim/io/convex_hull.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/result.h"

namespace rigid_body_sim::io {

// Pieces at most when a cavity needs them: past max_pieces, a piece whose
// hull takes in empty space farther than one wall thickness from the mesh
// is still cut, up to this many pieces (the helper's reply holds at most
// kMaxPieces = 64).
inline constexpr int kMaxCavityPieces = 64;

struct DecompositionOptions {
  // Count, [1000, 4e6]: voxels in the mesh's bounding box at least. They
  // set the candidate cut planes (one per voxel layer) and the balance
  // term. A mesh with thin walls gets more, up to 4e6, so that its wall
  // thickness spans at least 2.5 voxels.
  int voxel_count = 100000;
  // Count, [1, 64]: pieces at most that the concavity rule makes; a cavity
  // may grow them to kMaxCavityPieces.
  int max_pieces = 32;
  // Dimensionless, (0, 1]: a piece whose hull volume exceeds its own volume
  // by more than this fraction of the mesh volume is cut again.
  double max_concavity = 0.01;
  // Dimensionless, [0, 1]: weight of the balance term |V_left - V_right| / V.
  double balance_weight = 0.05;
  // Dimensionless, [0, 1): two touching pieces merge when the hull of both
  // exceeds the sum of their hulls by less than this fraction of the mesh
  // volume.
  double merge_volume = 0.002;
  // Dimensionless, (0, 1]: kAuto decomposes a closed mesh whose volume over
  // its hull's volume is below this; above it the mesh stays its hull.
  double convex_ratio = 0.9;
  HullOptions hull;  // for every piece's hull
};

// Ok, or a message naming the first field outside its range.
physics::Status CheckDecompositionOptions(const DecompositionOptions& options);

// The convex pieces of a closed mesh (every edge shared by two triangles).
// Their union covers the mesh; each piece lies inside the hull of the part
// of the mesh in its cell. Fails with a message on an open or degenerate
// mesh or on invalid options.
physics::Result<std::vector<physics::ConvexPolyhedron>> DecomposeConvex(
    const physics::TriangleMesh& mesh, const DecompositionOptions& options);

enum class PiecesRule {
  // Decompose a closed mesh of at most kMaxAutoTriangles triangles whose
  // volume / hull volume < convex_ratio; else its hull.
  kAuto,
  kAlways,  // decompose; the mesh must be closed
};

// Triangles at most that kAuto decomposes. The cost grows about linearly
// with them (each candidate cut clips the triangles over the piece): about
// 4.4 s of CPU for a cup of 8,000 triangles, within the mesh helper's
// default 10 s.
inline constexpr std::size_t kMaxAutoTriangles = 10000;

// The pieces a moving mesh collides as: one hull (an open mesh, or a nearly
// convex one under kAuto), or DecomposeConvex's pieces.
physics::Result<std::vector<physics::ConvexPolyhedron>> ConvexPieces(
    const physics::TriangleMesh& mesh, const DecompositionOptions& options, PiecesRule rule);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_CONVEX_DECOMPOSITION_H_
