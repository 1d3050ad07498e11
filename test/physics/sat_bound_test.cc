// The separating-axis test skipped on a bound (CollidePolyhedra,
// SeparatingWitness::distance_bound). Two references: the full test from
// the same cached feature must give the skipped call's contact bit for bit,
// over random walks of polyhedron pairs near contact; and the bound must
// hold against the test's separation and GJK's distance after random
// motions.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "physics/collision/narrow_phase.h"
#include "physics/collision/polyhedron_collision.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "support/gjk.h"

namespace rigid_body_sim::physics {
namespace {

constexpr double kContactDistance = 0.02;  // m, a margin like the world's

std::vector<std::shared_ptr<const ConvexPolyhedron>> Shapes() {
  return {std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3(1.0, 1.0, 1.0))),
          std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3(1.2, 0.7, 0.4))),
          std::make_shared<const ConvexPolyhedron>(MakeCylinderPolyhedron(0.4, 0.9, 7))};
}

Quat RandomRotation(std::mt19937_64* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Quat(normal(*rng), normal(*rng), normal(*rng), normal(*rng)).normalized();
}

double Reach(const ConvexPolyhedron& shape) {
  double reach = 0.0;
  for (const Vec3& v : shape.vertices) reach = std::max(reach, v.norm());
  return reach;
}

// A pose of B, turned at random, whose test separation from A (at the
// identity) is `separation`, found by bisection along a random direction.
Pose PlaceNear(const ConvexPolyhedron& a, const ConvexPolyhedron& b, double separation,
               std::mt19937_64* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Vec3 direction = Vec3(normal(*rng), normal(*rng), normal(*rng)).normalized();
  Pose pose{Vec3::Zero(), RandomRotation(rng)};
  double inside = 0.0;
  double outside = Reach(a) + Reach(b) + 1.0;
  for (int k = 0; k < 60; ++k) {
    pose.translation = 0.5 * (inside + outside) * direction;
    const double s = QueryPolyhedronSeparation(a, Pose::Identity(), b, pose).separation;
    (s < separation ? inside : outside) = 0.5 * (inside + outside);
  }
  return pose;
}

// B moved by a random step: a translation of length `shift` and a turn
// that moves B's farthest vertex `turn` far.
Pose RandomStep(const Pose& pose, double shift, double turn, double reach, std::mt19937_64* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Vec3 translation = Vec3(normal(*rng), normal(*rng), normal(*rng)).normalized() * shift;
  const Vec3 axis = Vec3(normal(*rng), normal(*rng), normal(*rng)).normalized();
  const Quat rotation(Eigen::AngleAxisd(turn / reach, axis));
  return Pose{pose.translation + translation, (rotation * pose.rotation).normalized()};
}

struct Call {
  bool touching = false;
  SeparatingWitness witness;
  ContactManifold manifold;
  CollideStats stats;
};

Call CollideAt(const ShapeGeometry& a, const ShapeGeometry& b, const Pose& b_pose,
               const SeparatingWitness& cached) {
  Call call;
  call.witness = cached;
  const CollideInput input{&a, Pose::Identity(), &b, b_pose, kContactDistance};
  call.touching = Collide(input, &call.witness, &call.manifold, &call.stats);
  return call;
}

void ExpectSameContact(const Call& skipped, const Call& full) {
  ASSERT_EQ(skipped.touching, full.touching);
  EXPECT_EQ(skipped.witness.type, full.witness.type);
  EXPECT_EQ(skipped.witness.index_a, full.witness.index_a);
  EXPECT_EQ(skipped.witness.index_b, full.witness.index_b);
  ASSERT_EQ(skipped.manifold.point_count, full.manifold.point_count);
  if (skipped.manifold.point_count == 0) return;
  EXPECT_EQ(skipped.manifold.normal_world, full.manifold.normal_world);
  for (int i = 0; i < full.manifold.point_count; ++i) {
    EXPECT_EQ(skipped.manifold.points[i].position_world, full.manifold.points[i].position_world);
    EXPECT_EQ(skipped.manifold.points[i].separation, full.manifold.points[i].separation);
    EXPECT_EQ(skipped.manifold.points[i].feature, full.manifold.points[i].feature);
  }
}

// Random walks of B near A, each with its own step size from 0.1 um to
// 1 cm, some only turning and some only shifting: each call with the
// carried witness (which may skip the test) against a call from the same
// cached feature with no bound (which runs it). The small steps skip; the
// large ones cross the points where the defining feature changes, which a
// bound too low would skip.
TEST(SatBoundTest, SkippedTestGivesTheFullTestsContactBitForBit) {
  std::mt19937_64 rng(1997);
  const std::vector<std::shared_ptr<const ConvexPolyhedron>> shapes = Shapes();
  std::uniform_real_distribution<double> start(-0.015, 0.015);
  std::uniform_real_distribution<double> exponent(-7.0, -2.0);
  std::uniform_real_distribution<double> jitter(0.5, 1.5);
  int calls = 0;
  int skipped_overlapping = 0;
  int skipped_apart = 0;
  int skipped_edges = 0;
  for (int walk = 0; walk < 600; ++walk) {
    const auto& a = shapes[walk % shapes.size()];
    const auto& b = shapes[(walk / shapes.size()) % shapes.size()];
    const ShapeGeometry shape_a = a;
    const ShapeGeometry shape_b = b;
    const double step_size = std::pow(10.0, exponent(rng));
    const double shift = walk % 3 == 1 ? 0.0 : step_size;
    const double turn = walk % 3 == 2 ? 0.0 : step_size;
    Pose pose = PlaceNear(*a, *b, start(rng), &rng);
    SeparatingWitness carried;
    for (int step = 0; step < 60; ++step) {
      SeparatingWitness unbounded = carried;
      unbounded.distance_bound = std::numeric_limits<double>::infinity();
      const Call full = CollideAt(shape_a, shape_b, pose, unbounded);
      const Call call = CollideAt(shape_a, shape_b, pose, carried);
      ASSERT_FALSE(full.stats.test_skipped);
      SCOPED_TRACE(::testing::Message() << "walk " << walk << ", step " << step);
      ExpectSameContact(call, full);
      if (call.stats.test_skipped) {
        ++(carried.distance_bound <= 0.0 ? skipped_overlapping : skipped_apart);
        if (carried.type == SeparatingWitness::Type::kEdges) ++skipped_edges;
      }
      ++calls;
      carried = call.witness;
      const double size = jitter(rng);
      pose = RandomStep(pose, size * shift, size * turn, Reach(*b), &rng);
    }
  }
  // The comparison means something only where the test was skipped.
  EXPECT_GT(skipped_overlapping, calls / 10);
  EXPECT_GT(skipped_apart, calls / 50);
  EXPECT_GT(skipped_edges, calls / 50);
}

// f <= D + |t - t0| + angle r_B after a motion, with D the bound recorded
// at the start; D is the test's separation for an overlap and at least
// GJK's distance apart.
TEST(SatBoundTest, BoundHoldsAfterRandomMotions) {
  std::mt19937_64 rng(2003);
  const std::vector<std::shared_ptr<const ConvexPolyhedron>> shapes = Shapes();
  std::uniform_real_distribution<double> start(-0.02, 0.015);
  std::uniform_real_distribution<double> exponent(-6.0, -1.0);
  int overlapping = 0;
  int apart = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const auto& a = shapes[trial % shapes.size()];
    const auto& b = shapes[(trial / shapes.size()) % shapes.size()];
    const Pose then = PlaceNear(*a, *b, start(rng), &rng);
    const Call first = CollideAt(ShapeGeometry(a), ShapeGeometry(b), then, SeparatingWitness());
    const double bound = first.witness.distance_bound;
    if (!std::isfinite(bound)) continue;
    const double separation = QueryPolyhedronSeparation(*a, Pose::Identity(), *b, then).separation;
    if (bound <= 0.0) {
      ++overlapping;
      EXPECT_EQ(bound, separation);
    } else {
      ++apart;
      const GjkResult gjk = GjkDistance({&a->vertices, Pose::Identity(), &b->vertices, then});
      EXPECT_GE(bound, gjk.distance - 1e-12) << "trial " << trial;
    }
    const double length = std::pow(10.0, exponent(rng));
    const Pose now = RandomStep(then, length, length, Reach(*b), &rng);
    const double motion = (now.translation - then.translation).norm() +
                          now.rotation.angularDistance(then.rotation) * Reach(*b);
    const double moved = QueryPolyhedronSeparation(*a, Pose::Identity(), *b, now).separation;
    EXPECT_LE(moved, bound + motion + 1e-9) << "trial " << trial << ", motion " << motion;
  }
  EXPECT_GT(overlapping, 1000);
  EXPECT_GT(apart, 300);
}

}  // namespace
}  // namespace rigid_body_sim::physics
