// Polyhedron against polyhedron: the cached witness, the separating-axis
// test (polyhedron_sat.cc) and the manifold of the defining feature
// (polyhedron_manifold.cc).
#include "physics/collision/polyhedron_collision.h"

#include <cassert>
#include <cmath>

#include "physics/collision/polyhedron_manifold.h"
#include "physics/collision/polyhedron_sat.h"

namespace rigid_body_sim::physics {
namespace {

// Feature selection for contacts prefers a face of A, then a face of B, then
// an edge pair, unless the next one separates more by this tolerance
// (kRelativeFeatureBias |best| + kAbsoluteFeatureBias): nearly equal axes
// otherwise flip from step to step and the manifold with them (Gregorius,
// GDC 2013). The cached feature of last step is preferred first.
constexpr double kRelativeFeatureBias = 0.05;
constexpr double kAbsoluteFeatureBias = 1e-5;  // m

}  // namespace

bool CollidePolyhedra(const PolyhedronPair& pair, SeparatingWitness* witness,
                      ContactManifold* manifold, CollideStats* stats) {
  assert(pair.a != nullptr && pair.b != nullptr && manifold != nullptr);
  assert(!pair.a->faces.empty() && !pair.b->faces.empty());
  CollideStats local_stats;
  if (stats == nullptr) stats = &local_stats;
  *stats = CollideStats{};
  manifold->point_count = 0;
  SeparatingWitness cached;
  if (witness != nullptr) cached = *witness;
  const double face_separation = FaceWitnessSeparation(pair, cached);
  if (face_separation > pair.contact_distance) {
    stats->witness_early_out = true;
    stats->gap = face_separation;
    return false;
  }
  const PairInA frame = MakePairInA(pair);

  // A face witness was measured above; an edge witness needs B in A's frame.
  Vec3 cached_edge_normal = Vec3::UnitZ();
  bool cached_edges_still_face = false;
  const double cached_separation =
      cached.type == SeparatingWitness::Type::kEdges
          ? EdgeWitnessSeparation(frame, cached, &cached_edge_normal, &cached_edges_still_face)
          : face_separation;
  if (cached_separation > pair.contact_distance) {
    stats->witness_early_out = true;
    stats->gap = cached_separation;
    return false;
  }

  const SatResult sat = RunSat(frame, pair.contact_distance);
  if (sat.separation > pair.contact_distance) {
    if (witness != nullptr) *witness = sat.witness;
    stats->gap = sat.separation;
    return false;
  }

  const double tolerance = kRelativeFeatureBias * std::abs(sat.separation) + kAbsoluteFeatureBias;
  const double acceptable = sat.separation - tolerance;
  SeparatingWitness chosen;
  double chosen_separation = 0.0;
  Vec3 chosen_edge_normal = sat.edges.normal_world;
  const bool cached_usable =
      cached.type != SeparatingWitness::Type::kEdges || cached_edges_still_face;
  if (cached.type != SeparatingWitness::Type::kNone && cached_usable &&
      cached_separation >= acceptable) {
    chosen = cached;
    chosen_separation = cached_separation;
    chosen_edge_normal = cached_edge_normal;
    stats->witness_kept = true;
  } else if (sat.face_a.separation >= acceptable) {
    chosen = {SeparatingWitness::Type::kFaceA, sat.face_a.face, -1};
  } else if (sat.face_b.separation >= acceptable) {
    chosen = {SeparatingWitness::Type::kFaceB, -1, sat.face_b.face};
  } else {
    chosen = {SeparatingWitness::Type::kEdges, sat.edges.edge_a, sat.edges.edge_b};
    chosen_separation = sat.edges.separation;
  }
  if (witness != nullptr) *witness = chosen;

  switch (chosen.type) {
    case SeparatingWitness::Type::kFaceA:
      return BuildFaceContact({pair.a, pair.world_from_a, chosen.index_a, pair.b, pair.world_from_b,
                               true, pair.contact_distance},
                              manifold);
    case SeparatingWitness::Type::kFaceB:
      return BuildFaceContact({pair.b, pair.world_from_b, chosen.index_b, pair.a, pair.world_from_a,
                               false, pair.contact_distance},
                              manifold);
    case SeparatingWitness::Type::kEdges:
      if (!(chosen_separation < pair.contact_distance)) return false;
      return BuildEdgeContact(pair, chosen.index_a, chosen.index_b, chosen_separation,
                              chosen_edge_normal, manifold);
    case SeparatingWitness::Type::kNone:
      break;
  }
  return false;
}

}  // namespace rigid_body_sim::physics
