// Narrow phase: box-box manifolds, sphere cases and half-spaces against
// analytic contact points, the witness cache, and GJK distances.
#include "physics/collision/narrow_phase.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "physics/collision/polyhedron_collision.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "support/gjk.h"

namespace rigid_body_sim::physics {
namespace {

constexpr double kExact = 1e-9;  // m: exact geometry up to rounding

ShapeGeometry Box(const Vec3& size) {
  return std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(size));
}

const ConvexPolyhedron& Hull(const ShapeGeometry& shape) {
  return *std::get<std::shared_ptr<const ConvexPolyhedron>>(shape);
}

Pose MakePose(const Vec3& translation, const Quat& rotation = Quat::Identity()) {
  return Pose{translation, rotation};
}

Quat AxisAngle(double angle, const Vec3& axis) {
  return Quat(Eigen::AngleAxisd(angle, axis.normalized()));
}

// A fixed, generic rigid motion applied to a whole configuration: contacts
// must move with it.
Pose Scramble() { return MakePose(Vec3(0.3, -1.7, 2.2), AxisAngle(0.9, Vec3(1, 2, -0.5))); }

struct Scene {
  ShapeGeometry a;
  Pose world_from_a;
  ShapeGeometry b;
  Pose world_from_b;
};

bool CollideScene(const Scene& scene, double contact_distance, ContactManifold* manifold,
                  SeparatingWitness* witness = nullptr, CollideStats* stats = nullptr) {
  const CollideInput input{&scene.a, scene.world_from_a, &scene.b, scene.world_from_b,
                           contact_distance};
  return Collide(input, witness, manifold, stats);
}

Scene Transformed(const Scene& scene, const Pose& world_from_old) {
  return {scene.a, world_from_old * scene.world_from_a, scene.b,
          world_from_old * scene.world_from_b};
}

// Each expected point must be matched by exactly one manifold point.
void ExpectPointsAt(const ContactManifold& manifold, const std::vector<Vec3>& expected,
                    double tolerance) {
  ASSERT_EQ(manifold.point_count, static_cast<int>(expected.size()));
  std::vector<bool> used(expected.size(), false);
  for (int i = 0; i < manifold.point_count; ++i) {
    bool matched = false;
    for (std::size_t k = 0; k < expected.size(); ++k) {
      if (!used[k] && (manifold.points[i].position_world - expected[k]).norm() < tolerance) {
        used[k] = true;
        matched = true;
        break;
      }
    }
    EXPECT_TRUE(matched) << "unexpected point " << manifold.points[i].position_world.transpose();
  }
}

// A 1 m cube 1 cm into the top of a 2 x 2 x 1 box, offset so that only the
// rectangle x in [0.2, 1], y in [-0.1, 0.9] overlaps. The contact plane is
// midway, z = 0.495.
Scene FaceOnFace() {
  return {Box(Vec3(1, 1, 1)), MakePose(Vec3(0.7, 0.4, 0.99)), Box(Vec3(2, 2, 1)),
          MakePose(Vec3::Zero())};
}

TEST(NarrowPhaseBoxTest, FaceOnFaceOffsetGivesOverlapRectangleCorners) {
  for (const Pose& world_from_scene : {Pose::Identity(), Scramble()}) {
    const Scene scene = Transformed(FaceOnFace(), world_from_scene);
    ContactManifold manifold;
    ASSERT_TRUE(CollideScene(scene, 0.0, &manifold));
    std::vector<Vec3> corners;
    for (const Vec3& corner : {Vec3(0.2, -0.1, 0.495), Vec3(1.0, -0.1, 0.495),
                               Vec3(1.0, 0.9, 0.495), Vec3(0.2, 0.9, 0.495)}) {
      corners.push_back(world_from_scene * corner);
    }
    ExpectPointsAt(manifold, corners, kExact);
    EXPECT_NEAR((manifold.normal_world - world_from_scene.rotation * Vec3::UnitZ()).norm(), 0.0,
                kExact);
    std::set<std::uint64_t> keys;
    for (int i = 0; i < manifold.point_count; ++i) {
      EXPECT_NEAR(manifold.points[i].separation, -0.01, kExact);
      keys.insert(manifold.points[i].feature.Key());
    }
    EXPECT_EQ(keys.size(), 4u) << "feature ids must tell the points apart";
  }
}

TEST(NarrowPhaseBoxTest, SwappingShapesFlipsTheNormalAndSwapsNothingElse) {
  const Scene scene = FaceOnFace();
  const Scene swapped{scene.b, scene.world_from_b, scene.a, scene.world_from_a};
  ContactManifold forward;
  ContactManifold backward;
  ASSERT_TRUE(CollideScene(scene, 0.0, &forward));
  ASSERT_TRUE(CollideScene(swapped, 0.0, &backward));
  EXPECT_NEAR((forward.normal_world + backward.normal_world).norm(), 0.0, kExact);
  std::vector<Vec3> positions;
  for (int i = 0; i < forward.point_count; ++i)
    positions.push_back(forward.points[i].position_world);
  ExpectPointsAt(backward, positions, kExact);
}

TEST(NarrowPhaseBoxTest, FeatureIdsAreStableUnderSmallMotion) {
  const Scene scene = FaceOnFace();
  Scene moved = scene;
  moved.world_from_a =
      MakePose(Vec3(1e-6, -2e-6, 1e-6), AxisAngle(1e-5, Vec3(1, 1, 0))) * scene.world_from_a;
  ContactManifold before;
  ContactManifold after;
  SeparatingWitness witness;
  ASSERT_TRUE(CollideScene(scene, 0.0, &before, &witness));
  ASSERT_TRUE(CollideScene(moved, 0.0, &after, &witness));
  ASSERT_EQ(before.point_count, after.point_count);
  for (int i = 0; i < before.point_count; ++i) {
    bool found = false;
    for (int k = 0; k < after.point_count; ++k) {
      if (after.points[k].feature == before.points[i].feature) {
        found = true;
        // The same feature pair is the same point moved by about 1e-5 m.
        EXPECT_LT((after.points[k].position_world - before.points[i].position_world).norm(), 3e-5);
      }
    }
    EXPECT_TRUE(found) << "feature " << before.points[i].feature.Key() << " disappeared";
  }
}

// Unit cube B turned 45 deg about x has its top edge along x at
// z = sqrt(2)/2; cube A turned 45 deg about y has its bottom edge along y.
// A's centre at z = sqrt(2) - 0.01 makes the edges cross at 90 deg, 1 cm
// deep. Closest points: (0.1, 0, sqrt(2)/2 - 0.01) on A and
// (0.1, 0, sqrt(2)/2) on B.
Scene EdgeAcrossEdge(double gap) {
  const double h = std::sqrt(0.5);
  return {Box(Vec3(1, 1, 1)),
          MakePose(Vec3(0.1, -0.2, 2 * h + gap), AxisAngle(kPi / 4, Vec3::UnitY())),
          Box(Vec3(1, 1, 1)), MakePose(Vec3::Zero(), AxisAngle(kPi / 4, Vec3::UnitX()))};
}

TEST(NarrowPhaseBoxTest, EdgeAcrossEdgeGivesOnePointAtTheClosestPoints) {
  const double h = std::sqrt(0.5);
  for (const Pose& world_from_scene : {Pose::Identity(), Scramble()}) {
    const Scene scene = Transformed(EdgeAcrossEdge(-0.01), world_from_scene);
    ContactManifold manifold;
    ASSERT_TRUE(CollideScene(scene, 0.0, &manifold));
    const Vec3 on_a(0.1, 0.0, h - 0.01);
    const Vec3 on_b(0.1, 0.0, h);
    ExpectPointsAt(manifold, {world_from_scene * (0.5 * (on_a + on_b))}, kExact);
    EXPECT_NEAR(manifold.points[0].separation, -0.01, kExact);
    EXPECT_EQ(manifold.points[0].feature.type, FeatureType::kEdgeEdge);
    EXPECT_NEAR((manifold.normal_world - world_from_scene.rotation * Vec3::UnitZ()).norm(), 0.0,
                kExact);
  }
}

// A unit cube standing on a corner (its diagonal vertical) 1 cm into the top
// face of a 4 x 4 x 1 slab: one vertex/face point, 5 mm below z = 0.5.
TEST(NarrowPhaseBoxTest, VertexIntoFaceGivesOnePoint) {
  // Turning (1, 1, 1) onto +z about (1, -1, 0) also turns (-1, -1, -1) onto -z.
  const Quat corner_down = AxisAngle(std::acos(1 / std::sqrt(3.0)), Vec3(1, -1, 0));
  const double half_diagonal = std::sqrt(3.0) / 2;
  const Scene scene{Box(Vec3(1, 1, 1)),
                    MakePose(Vec3(0.3, -0.4, 0.5 + half_diagonal - 0.01), corner_down),
                    Box(Vec3(4, 4, 1)), MakePose(Vec3::Zero())};
  ContactManifold manifold;
  ASSERT_TRUE(CollideScene(scene, 0.0, &manifold));
  ExpectPointsAt(manifold, {Vec3(0.3, -0.4, 0.495)}, kExact);
  EXPECT_NEAR(manifold.points[0].separation, -0.01, kExact);
  const FeatureId feature = manifold.points[0].feature;
  ASSERT_EQ(feature.type, FeatureType::kVertexFace);
  // Vertex 0 of a box is the (-,-,-) corner, which points down here.
  EXPECT_EQ(feature.index_a, 0);
  EXPECT_NEAR((Hull(scene.b).faces[feature.index_b].normal - Vec3::UnitZ()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((manifold.normal_world - Vec3::UnitZ()).norm(), 0.0, kExact);
}

// The axis the test reports must put every vertex of A on one side and every
// vertex of B on the other: min over A of n.x - max over B of n.y > 0.
double ProjectedGap(const Scene& scene, const Vec3& normal_world) {
  double min_a = std::numeric_limits<double>::infinity();
  double max_b = -std::numeric_limits<double>::infinity();
  for (const Vec3& v : Hull(scene.a).vertices) {
    min_a = std::min(min_a, normal_world.dot(scene.world_from_a * v));
  }
  for (const Vec3& v : Hull(scene.b).vertices) {
    max_b = std::max(max_b, normal_world.dot(scene.world_from_b * v));
  }
  return min_a - max_b;
}

TEST(NarrowPhaseBoxTest, SeparatedByOneMillimetreGivesNoContactAndASeparatingAxis) {
  Scene stacked = FaceOnFace();
  stacked.world_from_a.translation.z() = 1.001;
  const Scene crossed = EdgeAcrossEdge(0.001);
  for (const Scene& base : {stacked, crossed}) {
    for (const Pose& world_from_scene : {Pose::Identity(), Scramble()}) {
      const Scene scene = Transformed(base, world_from_scene);
      ContactManifold manifold;
      SeparatingWitness witness;
      EXPECT_FALSE(CollideScene(scene, 5e-4, &manifold, &witness));
      EXPECT_EQ(manifold.point_count, 0);
      const SatResult sat = QueryPolyhedronSeparation(Hull(scene.a), scene.world_from_a,
                                                      Hull(scene.b), scene.world_from_b);
      EXPECT_NEAR(sat.separation, 0.001, kExact);
      EXPECT_NEAR(ProjectedGap(scene, sat.normal_world), 0.001, kExact);
      EXPECT_EQ(witness.type, sat.witness.type);
    }
  }
}

TEST(NarrowPhaseWitnessTest, SeparatedPairTakesTheEarlyOutOnTheSecondCall) {
  Scene scene = EdgeAcrossEdge(0.001);
  ContactManifold manifold;
  SeparatingWitness witness;
  CollideStats stats;
  EXPECT_FALSE(CollideScene(scene, 0.0, &manifold, &witness, &stats));
  EXPECT_FALSE(stats.witness_early_out);
  EXPECT_EQ(witness.type, SeparatingWitness::Type::kEdges);
  EXPECT_FALSE(CollideScene(scene, 0.0, &manifold, &witness, &stats));
  EXPECT_TRUE(stats.witness_early_out);
  EXPECT_EQ(manifold.point_count, 0);
  // Moving into contact: the cached axis no longer separates, the full test
  // runs and finds the edge contact.
  scene = EdgeAcrossEdge(-0.01);
  EXPECT_TRUE(CollideScene(scene, 0.0, &manifold, &witness, &stats));
  EXPECT_FALSE(stats.witness_early_out);
  EXPECT_EQ(manifold.point_count, 1);
}

// The gap a separated pair reports is a lower bound on the true distance
// (GJK), whichever test found it: the full separating-axis test on the
// first call, the cached witness on the second, after a small motion. The
// narrow phase skips a pair until the bodies have moved by that much.
TEST(NarrowPhaseWitnessTest, ReportedGapIsALowerBoundOnTheDistance) {
  const ShapeGeometry box = Box(Vec3(1.0, 0.6, 0.3));
  const ShapeGeometry other = Box(Vec3(0.4, 0.8, 1.2));
  std::uint32_t state = 12345;
  auto uniform = [&state](double low, double high) {
    state = state * 1664525u + 1013904223u;
    return low + (high - low) * (state >> 8) / double(1u << 24);
  };
  auto random_rotation = [&] {
    return AxisAngle(uniform(0.0, kPi), Vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)));
  };
  int tested = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Scene scene{box, MakePose(Vec3::Zero(), random_rotation()), other,
                MakePose(Vec3(uniform(-1.5, 1.5), uniform(-1.5, 1.5), uniform(-1.5, 1.5)),
                         random_rotation())};
    SeparatingWitness witness;
    for (int call = 0; call < 2; ++call) {
      ContactManifold manifold;
      CollideStats stats;
      if (CollideScene(scene, 0.0, &manifold, &witness, &stats)) break;
      const GjkInput input{&Hull(scene.a).vertices, scene.world_from_a, &Hull(scene.b).vertices,
                           scene.world_from_b};
      const GjkResult distance = GjkDistance(input);
      ASSERT_TRUE(std::isfinite(stats.gap)) << "trial " << trial << ", call " << call;
      EXPECT_GT(stats.gap, 0.0);
      EXPECT_LE(stats.gap, distance.distance + kExact) << "trial " << trial << ", call " << call;
      ++tested;
      scene.world_from_b.translation += Vec3(0.01, -0.02, 0.015);
      scene.world_from_b.rotation = AxisAngle(0.02, Vec3(1, 1, 0)) * scene.world_from_b.rotation;
    }
  }
  EXPECT_GT(tested, 200);
}

TEST(NarrowPhaseWitnessTest, TouchingPairKeepsTheCachedFeatureAndTheSameManifold) {
  for (const Scene& scene : {FaceOnFace(), EdgeAcrossEdge(-0.01)}) {
    ContactManifold first;
    ContactManifold second;
    SeparatingWitness witness;
    CollideStats stats;
    ASSERT_TRUE(CollideScene(scene, 0.0, &first, &witness, &stats));
    EXPECT_FALSE(stats.witness_kept);
    const SeparatingWitness after_first = witness;
    ASSERT_TRUE(CollideScene(scene, 0.0, &second, &witness, &stats));
    EXPECT_TRUE(stats.witness_kept);
    EXPECT_EQ(witness.type, after_first.type);
    EXPECT_EQ(witness.index_a, after_first.index_a);
    EXPECT_EQ(witness.index_b, after_first.index_b);
    ASSERT_EQ(first.point_count, second.point_count);
    EXPECT_EQ(first.normal_world, second.normal_world);
    for (int i = 0; i < first.point_count; ++i) {
      EXPECT_EQ(first.points[i].position_world, second.points[i].position_world);
      EXPECT_EQ(first.points[i].separation, second.points[i].separation);
      EXPECT_EQ(first.points[i].feature, second.points[i].feature);
    }
  }
}

TEST(NarrowPhaseSphereTest, SphereSphere) {
  const Vec3 centre_b(1, 2, 3);
  const Vec3 direction = Vec3(0.6, 0.0, 0.8);
  const Vec3 centre_a = centre_b + 1.1 * direction;
  const Scene scene{Sphere{0.5}, MakePose(centre_a), Sphere{0.7}, MakePose(centre_b)};
  ContactManifold manifold;
  ASSERT_TRUE(CollideScene(scene, 0.0, &manifold));
  EXPECT_NEAR((manifold.normal_world - direction).norm(), 0.0, 1e-12);
  EXPECT_NEAR(manifold.points[0].separation, 1.1 - 1.2, 1e-12);
  // Surface points c_a - 0.5 n and c_b + 0.7 n; the contact is midway.
  const Vec3 expected = 0.5 * ((centre_a - 0.5 * direction) + (centre_b + 0.7 * direction));
  ExpectPointsAt(manifold, {expected}, 1e-12);
  EXPECT_FALSE(CollideScene(scene, -0.1 - 1e-9, &manifold));
  EXPECT_EQ(manifold.point_count, 0);
}

struct SphereBoxCase {
  Vec3 centre_in_box;   // m, box frame
  double radius;        // m
  Vec3 normal_in_box;   // expected, from the box to the sphere
  double separation;    // m, expected
  Vec3 surface_in_box;  // expected closest point of the box
};

// A 2 x 1 x 1 box (half extents 1, 0.5, 0.5) under a generic pose, with the
// sphere over a face, beside an edge, beyond a vertex, and inside.
TEST(NarrowPhaseSphereTest, SphereBoxMatchesClosestFeature) {
  const double a = 0.1;
  const std::vector<SphereBoxCase> cases = {
      {Vec3(0.2, 0.1, 0.8), 0.35, Vec3::UnitZ(), 0.3 - 0.35, Vec3(0.2, 0.1, 0.5)},
      {Vec3(1 + a, 0.2, 0.5 + a), 0.2, Vec3(1, 0, 1).normalized(), a * std::sqrt(2.0) - 0.2,
       Vec3(1, 0.2, 0.5)},
      {Vec3(1 + a, 0.5 + a, 0.5 + a), 0.2, Vec3(1, 1, 1).normalized(), a * std::sqrt(3.0) - 0.2,
       Vec3(1, 0.5, 0.5)},
      {Vec3(0.3, 0.1, 0.35), 0.1, Vec3::UnitZ(), -0.15 - 0.1, Vec3(0.3, 0.1, 0.5)},
  };
  const Pose world_from_box = Scramble();
  for (const SphereBoxCase& c : cases) {
    const Vec3 centre = world_from_box * c.centre_in_box;
    const Vec3 normal = world_from_box.rotation * c.normal_in_box;
    const Vec3 expected = 0.5 * (world_from_box * c.surface_in_box + centre - c.radius * normal);
    const Scene sphere_first{Sphere{c.radius}, MakePose(centre), Box(Vec3(2, 1, 1)),
                             world_from_box};
    ContactManifold manifold;
    ASSERT_TRUE(CollideScene(sphere_first, 0.0, &manifold));
    EXPECT_NEAR((manifold.normal_world - normal).norm(), 0.0, 1e-12);
    EXPECT_NEAR(manifold.points[0].separation, c.separation, 1e-12);
    ExpectPointsAt(manifold, {expected}, 1e-12);
    // As B the sphere gets the opposite normal and the same point.
    const Scene box_first{sphere_first.b, world_from_box, sphere_first.a, MakePose(centre)};
    ASSERT_TRUE(CollideScene(box_first, 0.0, &manifold));
    EXPECT_NEAR((manifold.normal_world + normal).norm(), 0.0, 1e-12);
    EXPECT_NEAR(manifold.points[0].separation, c.separation, 1e-12);
    ExpectPointsAt(manifold, {expected}, 1e-12);
  }
}

TEST(NarrowPhaseHalfSpaceTest, SphereOnTiltedGround) {
  const Pose world_from_ground = MakePose(Vec3(0, 0, -1), AxisAngle(0.3, Vec3(1, 1, 0)));
  const Vec3 up = world_from_ground.rotation * Vec3::UnitZ();
  const Vec3 centre = world_from_ground * Vec3(0.4, -0.2, 0.25);
  const Scene scene{Sphere{0.3}, MakePose(centre), HalfSpace{}, world_from_ground};
  ContactManifold manifold;
  ASSERT_TRUE(CollideScene(scene, 0.0, &manifold));
  EXPECT_NEAR((manifold.normal_world - up).norm(), 0.0, 1e-12);
  EXPECT_NEAR(manifold.points[0].separation, -0.05, 1e-12);
  ExpectPointsAt(manifold, {world_from_ground * Vec3(0.4, -0.2, -0.025)}, 1e-12);
  const Scene swapped{HalfSpace{}, world_from_ground, Sphere{0.3}, MakePose(centre)};
  ASSERT_TRUE(CollideScene(swapped, 0.0, &manifold));
  EXPECT_NEAR((manifold.normal_world + up).norm(), 0.0, 1e-12);
  EXPECT_FALSE(CollideScene(scene, -0.06, &manifold));
}

// A unit cube turned by 0.1 rad about x: its two lowest vertices
// (x = +-0.5, y = -0.5, z = -0.5 in the box frame) are sin(0.1) ~ 0.1 m
// below the next two, so 2 cm of penetration gives exactly two points.
TEST(NarrowPhaseHalfSpaceTest, TiltedBoxOnGroundGivesItsLowestVertices) {
  const double angle = 0.1;
  const Quat tilt = AxisAngle(angle, Vec3::UnitX());
  const double lowest = -0.5 * (std::sin(angle) + std::cos(angle));
  const Pose world_from_box = MakePose(Vec3(0.2, 0.3, -lowest - 0.02), tilt);
  const Scene scene{Box(Vec3(1, 1, 1)), world_from_box, HalfSpace{}, Pose::Identity()};
  ContactManifold manifold;
  ASSERT_TRUE(CollideScene(scene, 0.0, &manifold));
  std::vector<Vec3> expected;
  for (double x : {-0.5, 0.5}) {
    const Vec3 vertex = world_from_box * Vec3(x, -0.5, -0.5);
    EXPECT_NEAR(vertex.z(), -0.02, 1e-12);
    expected.push_back(Vec3(vertex.x(), vertex.y(), -0.01));
  }
  ExpectPointsAt(manifold, expected, 1e-12);
  EXPECT_NE(manifold.points[0].feature.index_a, manifold.points[1].feature.index_a);
  EXPECT_EQ(manifold.points[0].feature.type, FeatureType::kVertexFace);
  const Scene swapped{HalfSpace{}, Pose::Identity(), scene.a, world_from_box};
  ASSERT_TRUE(CollideScene(swapped, 0.0, &manifold));
  EXPECT_EQ(manifold.points[0].feature.type, FeatureType::kFaceVertex);
  EXPECT_NEAR((manifold.normal_world + Vec3::UnitZ()).norm(), 0.0, 1e-12);
}

// A 32-sided prism lying almost flat (tilted 1e-3 rad about x) puts all 32
// bottom vertices in contact; the reduction keeps the deepest (angle 270
// deg), its antipode, and the two at 0 and 180 deg: the inscribed square,
// area 2 r^2 cos(tilt) seen from above.
TEST(NarrowPhaseHalfSpaceTest, ManyPointsReduceToTheDeepestAndLargestQuad) {
  const double radius = 0.5;
  const double tilt = 1e-3;
  const ShapeGeometry prism =
      std::make_shared<const ConvexPolyhedron>(MakeCylinderPolyhedron(radius, 0.2, 32));
  const Pose world_from_prism = MakePose(Vec3(0, 0, 0.099), AxisAngle(tilt, Vec3::UnitX()));
  const Scene scene{prism, world_from_prism, HalfSpace{}, Pose::Identity()};
  ContactManifold manifold;
  ASSERT_TRUE(CollideScene(scene, 0.0, &manifold));
  ASSERT_EQ(manifold.point_count, 4);
  double deepest = 0.0;
  for (const Vec3& v : Hull(prism).vertices) {
    deepest = std::min(deepest, (world_from_prism * v).z());
  }
  EXPECT_NEAR(manifold.points[0].separation, deepest, 1e-12);
  std::vector<Vec3> corners;
  for (int i = 0; i < 4; ++i) corners.push_back(manifold.points[i].position_world);
  std::sort(corners.begin(), corners.end(), [](const Vec3& p, const Vec3& q) {
    return std::atan2(p.y(), p.x()) < std::atan2(q.y(), q.x());
  });
  double area = 0.0;
  for (int i = 0; i < 4; ++i) {
    const Vec3& p = corners[i];
    const Vec3& q = corners[(i + 1) % 4];
    area += 0.5 * (p.x() * q.y() - q.x() * p.y());
  }
  EXPECT_NEAR(area, 2 * radius * radius * std::cos(tilt), 1e-12);
}

TEST(GjkTest, DistancesBetweenBoxesMatchGeometry) {
  const ConvexPolyhedron cube = MakeBoxPolyhedron(Vec3(1, 1, 1));
  GjkInput input{&cube.vertices, Pose::Identity(), &cube.vertices, Pose::Identity()};
  // Face to face, 0.3 m apart along x.
  input.world_from_b = MakePose(Vec3(1.3, 0.2, -0.1));
  GjkResult result = GjkDistance(input);
  EXPECT_FALSE(result.overlapping);
  EXPECT_NEAR(result.distance, 0.3, 1e-12);
  EXPECT_NEAR(result.point_a_world.x(), 0.5, 1e-12);
  EXPECT_NEAR(result.point_b_world.x(), 0.8, 1e-12);
  // Corner to corner: (0.5, 0.5, 0.5) to (0.7, 0.8, 0.9).
  input.world_from_b = MakePose(Vec3(1.2, 1.3, 1.4));
  result = GjkDistance(input);
  EXPECT_NEAR(result.distance, std::sqrt(0.29), 1e-12);
  EXPECT_NEAR((result.point_a_world - Vec3(0.5, 0.5, 0.5)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((result.point_b_world - Vec3(0.7, 0.8, 0.9)).norm(), 0.0, 1e-12);
  // Edge to edge, crossed: the EdgeAcrossEdge scene lifted 1 cm.
  const double h = std::sqrt(0.5);
  input.world_from_a = MakePose(Vec3(0.1, -0.2, 2 * h + 0.01), AxisAngle(kPi / 4, Vec3::UnitY()));
  input.world_from_b = MakePose(Vec3::Zero(), AxisAngle(kPi / 4, Vec3::UnitX()));
  result = GjkDistance(input);
  EXPECT_NEAR(result.distance, 0.01, 1e-12);
  // Overlapping by 1 cm.
  input.world_from_a = MakePose(Vec3(0.1, -0.2, 2 * h - 0.01), AxisAngle(kPi / 4, Vec3::UnitY()));
  result = GjkDistance(input);
  EXPECT_TRUE(result.overlapping);
  EXPECT_EQ(result.distance, 0.0);
}

}  // namespace
}  // namespace rigid_body_sim::physics
