// The separating-axis test on 10,000 random pairs of convex polyhedra,
// checked against independent references: GJK distance for separated
// pairs, and for penetrating pairs a brute-force maximum over all face
// normals and all edge-direction crosses (no Gauss-map pruning), plus GJK
// after translating A out by the reported depth.
#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "physics/collision/narrow_phase.h"
#include "physics/collision/polyhedron_collision.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "support/gjk.h"

namespace rigid_body_sim::physics {
namespace {

using Triangle = std::array<int, 3>;

// Incremental convex hull (Clarkson and Shor 1989 without conflict lists):
// start from a tetrahedron, and for each further point remove the faces
// that see it and close the hole with triangles from the horizon edges to
// the point. Quadratic, which is plenty for a few dozen points.
std::vector<Triangle> IncrementalHull(const std::vector<Vec3>& points) {
  const int n = static_cast<int>(points.size());
  double scale = 0.0;
  for (const Vec3& p : points) scale = std::max(scale, p.norm());
  const double eps = 1e-10 * scale;
  const auto above = [&](const Triangle& t, const Vec3& p) {
    const Vec3 normal = (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]);
    return normal.normalized().dot(p - points[t[0]]);
  };
  // A first tetrahedron: the points are random, so 0..3 are independent.
  std::vector<Triangle> faces = {{0, 1, 2}, {0, 3, 1}, {1, 3, 2}, {2, 3, 0}};
  if (above(faces[0], points[3]) > 0.0) {
    for (Triangle& t : faces) std::swap(t[1], t[2]);
  }
  for (int i = 4; i < n; ++i) {
    std::vector<bool> visible(faces.size());
    bool any = false;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      visible[f] = above(faces[f], points[i]) > eps;
      any = any || visible[f];
    }
    if (!any) continue;
    std::map<std::pair<int, int>, int> face_of_edge;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      for (int k = 0; k < 3; ++k) face_of_edge[{faces[f][k], faces[f][(k + 1) % 3]}] = f;
    }
    std::vector<Triangle> kept;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      if (!visible[f]) kept.push_back(faces[f]);
    }
    for (std::size_t f = 0; f < faces.size(); ++f) {
      if (!visible[f]) continue;
      for (int k = 0; k < 3; ++k) {
        const int u = faces[f][k];
        const int v = faces[f][(k + 1) % 3];
        if (!visible[face_of_edge.at({v, u})]) kept.push_back({u, v, i});
      }
    }
    faces = std::move(kept);
  }
  return faces;
}

Quat RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Quat q(normal(rng), normal(rng), normal(rng), normal(rng));
  q.normalize();
  return q;
}

Vec3 RandomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  return Vec3(normal(rng), normal(rng), normal(rng)).normalized();
}

// Boxes, prisms and random polytopes of varied proportions.
std::vector<ConvexPolyhedron> MakePool(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> size(0.1, 2.0);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<ConvexPolyhedron> pool;
  for (int i = 0; i < 40; ++i)
    pool.push_back(MakeBoxPolyhedron(Vec3(size(rng), size(rng), size(rng))));
  for (int i = 0; i < 30; ++i) {
    const int segments = 3 + static_cast<int>(rng() % 18);
    pool.push_back(MakeCylinderPolyhedron(0.5 * size(rng), size(rng), segments));
  }
  for (int i = 0; i < 80; ++i) {
    const int count = 6 + static_cast<int>(rng() % 11);
    const Vec3 semi_axes(0.5 * size(rng), 0.5 * size(rng), 0.5 * size(rng));
    const bool on_surface = i % 2 == 0;
    std::vector<Vec3> points;
    for (int k = 0; k < count; ++k) {
      const Vec3 p = on_surface ? Vec3(RandomUnit(rng)) : Vec3(unit(rng), unit(rng), unit(rng));
      points.push_back(p.cwiseProduct(semi_axes));
    }
    std::vector<std::vector<int>> faces;
    for (const Triangle& t : IncrementalHull(points)) faces.push_back({t[0], t[1], t[2]});
    Result<ConvexPolyhedron> hull = MakeConvexPolyhedron(points, faces);
    EXPECT_TRUE(hull.ok()) << hull.message();
    if (hull.ok()) pool.push_back(std::move(hull).value());
  }
  return pool;
}

double BoundingRadius(const ConvexPolyhedron& polyhedron) {
  double radius = 0.0;
  for (const Vec3& v : polyhedron.vertices) radius = std::max(radius, v.norm());
  return radius;
}

// s(n) = min over A of n.x - max over B of n.y, by plain loops.
double SeparationAlong(const std::vector<Vec3>& a_world, const std::vector<Vec3>& b_world,
                       const Vec3& n) {
  double min_a = std::numeric_limits<double>::infinity();
  double max_b = -std::numeric_limits<double>::infinity();
  for (const Vec3& x : a_world) min_a = std::min(min_a, n.dot(x));
  for (const Vec3& y : b_world) max_b = std::max(max_b, n.dot(y));
  return min_a - max_b;
}

std::vector<Vec3> EdgeDirectionsWorld(const ConvexPolyhedron& polyhedron, const Pose& pose) {
  std::vector<Vec3> directions;
  for (int e = 0; e < polyhedron.EdgeCount(); ++e) {
    directions.push_back(pose.rotation *
                         (polyhedron.vertices[polyhedron.half_edges[2 * e + 1].origin] -
                          polyhedron.vertices[polyhedron.half_edges[2 * e].origin]));
  }
  return directions;
}

// The maximum of s over both signs of every face normal and every
// non-parallel edge-edge cross: a superset of the Minkowski-face normals,
// where the maximum over all directions is attained when the shapes overlap.
double BruteForceSeparation(const ConvexPolyhedron& a, const Pose& world_from_a,
                            const ConvexPolyhedron& b, const Pose& world_from_b,
                            const std::vector<Vec3>& a_world, const std::vector<Vec3>& b_world) {
  std::vector<Vec3> axes;
  for (const auto& face : a.faces) axes.push_back(world_from_a.rotation * face.normal);
  for (const auto& face : b.faces) axes.push_back(world_from_b.rotation * face.normal);
  const std::vector<Vec3> edges_a = EdgeDirectionsWorld(a, world_from_a);
  const std::vector<Vec3> edges_b = EdgeDirectionsWorld(b, world_from_b);
  for (const Vec3& ea : edges_a) {
    for (const Vec3& eb : edges_b) {
      const Vec3 cross = ea.cross(eb);
      if (cross.norm() > 1e-12 * ea.norm() * eb.norm()) axes.push_back(cross.normalized());
    }
  }
  double best = -std::numeric_limits<double>::infinity();
  for (const Vec3& axis : axes) {
    best = std::max(best, SeparationAlong(a_world, b_world, axis));
    best = std::max(best, SeparationAlong(a_world, b_world, -axis));
  }
  return best;
}

GjkResult Distance(const ConvexPolyhedron& a, const Pose& world_from_a, const ConvexPolyhedron& b,
                   const Pose& world_from_b) {
  return GjkDistance({&a.vertices, world_from_a, &b.vertices, world_from_b});
}

TEST(RandomHullTest, SeparatingAxisTestAgreesWithIndependentReferences) {
  std::mt19937_64 rng(20130307);
  const std::vector<ConvexPolyhedron> pool = MakePool(rng);
  ASSERT_EQ(pool.size(), 150u);
  std::vector<std::shared_ptr<const ConvexPolyhedron>> shared;
  for (const ConvexPolyhedron& p : pool)
    shared.push_back(std::make_shared<const ConvexPolyhedron>(p));
  std::uniform_real_distribution<double> fraction(0.0, 1.0);

  int separated = 0;
  int penetrating = 0;
  int face_closest = 0;
  constexpr int kPairs = 10000;
  for (int pair = 0; pair < kPairs; ++pair) {
    const int ia = static_cast<int>(rng() % pool.size());
    const int ib = static_cast<int>(rng() % pool.size());
    const ConvexPolyhedron& a = pool[ia];
    const ConvexPolyhedron& b = pool[ib];
    const Pose world_from_b{Vec3(fraction(rng), fraction(rng), fraction(rng)), RandomRotation(rng)};
    const double reach = BoundingRadius(a) + BoundingRadius(b);
    const Pose world_from_a{
        world_from_b.translation + 0.9 * reach * fraction(rng) * RandomUnit(rng),
        RandomRotation(rng)};
    std::vector<Vec3> a_world;
    std::vector<Vec3> b_world;
    for (const Vec3& v : a.vertices) a_world.push_back(world_from_a * v);
    for (const Vec3& v : b.vertices) b_world.push_back(world_from_b * v);

    const SatResult sat = QueryPolyhedronSeparation(a, world_from_a, b, world_from_b);
    SCOPED_TRACE(::testing::Message() << "pair " << pair << " (" << ia << ", " << ib
                                      << "), SAT separation " << sat.separation);
    ASSERT_NEAR(sat.normal_world.norm(), 1.0, 1e-12);
    // The reported axis is the axis of the reported separation.
    ASSERT_NEAR(SeparationAlong(a_world, b_world, sat.normal_world), sat.separation, 1e-9);

    const GjkResult gjk = Distance(a, world_from_a, b, world_from_b);
    if (sat.separation > 0.0) {
      ++separated;
      ASSERT_FALSE(gjk.overlapping);
      ASSERT_GT(gjk.distance, 0.0);
      // Any axis separation is a lower bound of the distance; on a face of
      // A - B (vertex/face or edge/edge closest features) it is the distance.
      ASSERT_LE(sat.separation, gjk.distance + 1e-9);
      if (gjk.simplex_count == 3) {
        ++face_closest;
        ASSERT_NEAR(sat.separation, gjk.distance, 1e-6);
      }
    } else {
      ++penetrating;
      const double depth = -sat.separation;
      const double brute = BruteForceSeparation(a, world_from_a, b, world_from_b, a_world, b_world);
      ASSERT_NEAR(sat.separation, brute, 1e-6);
      Pose moved = world_from_a;
      moved.translation = world_from_a.translation + (depth + 1e-6) * sat.normal_world;
      const GjkResult out = Distance(a, moved, b, world_from_b);
      ASSERT_FALSE(out.overlapping);
      ASSERT_GT(out.distance, 0.0);
      moved.translation = world_from_a.translation + (depth - 1e-4) * sat.normal_world;
      ASSERT_TRUE(Distance(a, moved, b, world_from_b).overlapping);
    }

    // The full narrow phase agrees with the test: contact iff overlap, and
    // every point is no deeper than the chosen feature allows (the feature
    // bias accepts 5% + 10 um less than the best separation).
    const ShapeGeometry shape_a = shared[ia];
    const ShapeGeometry shape_b = shared[ib];
    ContactManifold manifold;
    SeparatingWitness witness;
    CollideStats stats;
    const CollideInput input{&shape_a, world_from_a, &shape_b, world_from_b, 0.0};
    const bool touching = Collide(input, &witness, &manifold, &stats);
    ASSERT_EQ(touching, sat.separation < 0.0);
    if (touching) {
      ASSERT_GE(manifold.point_count, 1);
      ASSERT_LE(manifold.point_count, 4);
      ASSERT_NEAR(manifold.normal_world.norm(), 1.0, 1e-12);
      for (int i = 0; i < manifold.point_count; ++i) {
        ASSERT_LT(manifold.points[i].separation, 0.0);
        ASSERT_GE(manifold.points[i].separation, 1.05 * sat.separation - 1e-5 - 1e-9);
      }
    }
    // The same poses again: a separating witness ends the call at once, a
    // contact witness is kept.
    Collide(input, &witness, &manifold, &stats);
    ASSERT_EQ(stats.witness_early_out, !touching);
    ASSERT_EQ(stats.witness_kept, touching);
  }
  std::cout << separated << " separated (" << face_closest << " closest on a face of A - B), "
            << penetrating << " penetrating pairs\n";
  // The sampling covers both outcomes and face-closest separations.
  EXPECT_GT(separated, kPairs / 5);
  EXPECT_GT(penetrating, kPairs / 5);
  EXPECT_GT(face_closest, kPairs / 20);
}

}  // namespace
}  // namespace rigid_body_sim::physics
