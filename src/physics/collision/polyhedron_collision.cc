// Polyhedron against polyhedron: the cached witness, the separating-axis
// test (polyhedron_sat.cc) and the manifold of the defining feature
// (polyhedron_manifold.cc).
#include "physics/collision/polyhedron_collision.h"

#include <cassert>
#include <cmath>
#include <limits>

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

// What SatBoundKeepsFeature adds to its bound for rounding and for the
// nearly parallel edge pairs that the test skips (kParallelSine, 1e-8 of an
// edge): kBoundSlack + kBoundRelativeSlack (r_B + |t|), m.
constexpr double kBoundSlack = 1e-9;
constexpr double kBoundRelativeSlack = 1e-7;

// The lowest separation a feature may have and still define the contact
// when the best axis separates by `best`. It rises with `best`.
double AcceptableSeparation(double best) {
  return best - (kRelativeFeatureBias * std::abs(best) + kAbsoluteFeatureBias);
}

// Whether the full separating-axis test, if run now, would keep the cached
// feature (of separation `cached_separation` now), proved without running
// it. Every axis's gap is at most the shapes' signed distance d, so the
// test's best f <= d. And d moves by at most as far as any point of B moves
// in A's frame, |t - t0| + angle(R R0^-1) r_B: the distance, and the depth
// of an overlap (the shortest translation that brings the shapes to touch,
// van den Bergen, "Proximity Queries and Penetration Depth Computation on
// 3D Game Objects", 2001, section 1), are both 1-Lipschitz in B's points.
// So with d0 <= D at the last test's pose (R0, t0)
// (SeparatingWitness::distance_bound), now f <= D + motion; where the
// cached feature is acceptable against that bound, and the bound is within
// the contact distance, the test would keep the cached feature, and the
// manifold is the one it would build.
bool SatBoundKeepsFeature(const PairInA& frame, const SeparatingWitness& cached,
                          double cached_separation, double contact_distance) {
  if (!(cached.distance_bound < contact_distance)) return false;
  const Pose& now = frame.a_from_b;
  const Pose& then = cached.a_from_b_at_test;
  const double motion = (now.translation - then.translation).norm() +
                        now.rotation.angularDistance(then.rotation) * frame.b_reach;
  const double slack = kBoundSlack + kBoundRelativeSlack * (frame.b_reach + now.translation.norm());
  const double bound = cached.distance_bound + motion + slack;
  return bound <= contact_distance && cached_separation >= AcceptableSeparation(bound);
}

// An upper bound on the shapes' signed distance d where the test found
// `sat` and chose `feature`: overlapping (f <= 0) and with every axis tested
// (`complete`: no early out), the face of A - B nearest the origin is a
// candidate, so d = f; apart, d is at most the distance between any two
// points of the shapes, such as the chosen edges' closest points. +infinity
// where neither applies.
double DistanceBound(const PairInA& frame, const SatResult& sat, const SeparatingWitness& feature,
                     bool complete) {
  if (complete && sat.separation <= 0.0) return sat.separation;
  if (feature.type != SeparatingWitness::Type::kEdges) {
    return std::numeric_limits<double>::infinity();
  }
  return EdgePairDistance(frame, feature.index_a, feature.index_b);
}

// The feature that defines the contact, with its separation and (edge
// pairs) its normal.
struct ChosenFeature {
  SeparatingWitness witness;
  double separation = 0.0;  // m, read for edge pairs only
  Vec3 edge_normal_world = Vec3::UnitZ();
};

// The cached feature if it is within the tolerance of the test's best, else
// the best in the order face of A, face of B, edges.
ChosenFeature ChooseFeature(const SatResult& sat, const ChosenFeature& cached, bool cached_usable,
                            CollideStats* stats) {
  const double acceptable = AcceptableSeparation(sat.separation);
  if (cached_usable && cached.separation >= acceptable) {
    stats->witness_kept = true;
    return cached;
  }
  ChosenFeature chosen;
  chosen.edge_normal_world = sat.edges.normal_world;
  if (sat.face_a.separation >= acceptable) {
    chosen.witness = {SeparatingWitness::Type::kFaceA, sat.face_a.face, -1};
  } else if (sat.face_b.separation >= acceptable) {
    chosen.witness = {SeparatingWitness::Type::kFaceB, -1, sat.face_b.face};
  } else {
    chosen.witness = {SeparatingWitness::Type::kEdges, sat.edges.edge_a, sat.edges.edge_b};
    chosen.separation = sat.edges.separation;
  }
  return chosen;
}

bool BuildContact(const PolyhedronPair& pair, const ChosenFeature& chosen,
                  ContactManifold* manifold) {
  const SeparatingWitness& feature = chosen.witness;
  switch (feature.type) {
    case SeparatingWitness::Type::kFaceA:
      return BuildFaceContact({pair.a, pair.world_from_a, feature.index_a, pair.b,
                               pair.world_from_b, true, pair.contact_distance},
                              manifold);
    case SeparatingWitness::Type::kFaceB:
      return BuildFaceContact({pair.b, pair.world_from_b, feature.index_b, pair.a,
                               pair.world_from_a, false, pair.contact_distance},
                              manifold);
    case SeparatingWitness::Type::kEdges:
      if (!(chosen.separation < pair.contact_distance)) return false;
      return BuildEdgeContact(pair, feature.index_a, feature.index_b, chosen.separation,
                              chosen.edge_normal_world, manifold);
    case SeparatingWitness::Type::kNone:
      break;
  }
  return false;
}

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
  ChosenFeature kept{cached, face_separation, Vec3::UnitZ()};
  bool cached_edges_still_face = false;
  if (cached.type == SeparatingWitness::Type::kEdges) {
    kept.separation =
        EdgeWitnessSeparation(frame, cached, &kept.edge_normal_world, &cached_edges_still_face);
  }
  if (kept.separation > pair.contact_distance) {
    stats->witness_early_out = true;
    stats->gap = kept.separation;
    return false;
  }
  const bool cached_usable =
      cached.type != SeparatingWitness::Type::kNone &&
      (cached.type != SeparatingWitness::Type::kEdges || cached_edges_still_face);

  ChosenFeature chosen;
  if (cached_usable &&
      SatBoundKeepsFeature(frame, cached, kept.separation, pair.contact_distance)) {
    chosen = kept;
    stats->witness_kept = true;
    stats->test_skipped = true;
  } else {
    const SatResult sat = RunSat(frame, pair.contact_distance);
    cached.a_from_b_at_test = frame.a_from_b;
    if (sat.separation > pair.contact_distance) {
      if (witness != nullptr) {
        *witness = sat.witness;
        witness->distance_bound = DistanceBound(frame, sat, sat.witness, /*complete=*/false);
        witness->a_from_b_at_test = frame.a_from_b;
      }
      stats->gap = sat.separation;
      return false;
    }
    chosen = ChooseFeature(sat, kept, cached_usable, stats);
    // No early out: the best separation is within the contact distance.
    cached.distance_bound = DistanceBound(frame, sat, chosen.witness, /*complete=*/true);
  }
  if (witness != nullptr) {
    *witness = chosen.witness;
    witness->distance_bound = cached.distance_bound;
    witness->a_from_b_at_test = cached.a_from_b_at_test;
  }
  return BuildContact(pair, chosen, manifold);
}

}  // namespace rigid_body_sim::physics
