#include "rigid_body_sim/io/convex_hull.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "../physics/mesh_fixtures.h"
#include "polyhedron_checks.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/mass_properties.h"

namespace rigid_body_sim::io {
namespace {

using physics::ConvexPolyhedron;
using physics::kPi;
using physics::Vec3;

std::set<std::array<double, 3>> AsSet(const std::vector<Vec3>& points) {
  std::set<std::array<double, 3>> set;
  for (const Vec3& p : points) set.insert({p.x(), p.y(), p.z()});
  return set;
}

Vec3 RandomUnitVector(std::mt19937_64& random) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Vec3(normal(random), normal(random), normal(random)).normalized();
}

double Volume(const ConvexPolyhedron& polyhedron) {
  return physics::PolyhedronMassProperties(1.0, polyhedron).mass;
}

TEST(ConvexHullTest, CubeWithInteriorPointsHasEightVerticesAndSixQuads) {
  std::vector<Vec3> points;
  for (int i = 0; i < 8; ++i) {
    points.emplace_back(i & 1 ? 0.5 : -0.5, i & 2 ? 0.5 : -0.5, i & 4 ? 0.5 : -0.5);
  }
  std::mt19937_64 random(1);
  std::uniform_real_distribution<double> inside(-0.499, 0.499);
  for (int i = 0; i < 1000; ++i)
    points.emplace_back(inside(random), inside(random), inside(random));

  const physics::Result<ConvexPolyhedron> hull = ComputeConvexHull(points);
  ASSERT_TRUE(hull.ok()) << hull.message();
  EXPECT_EQ(hull->vertices.size(), 8u);
  ASSERT_EQ(hull->faces.size(), 6u);
  for (int f = 0; f < 6; ++f) EXPECT_EQ(hull->FaceVertices(f).size(), 4u);
  EXPECT_EQ(hull->EdgeCount(), 12);
  EXPECT_EQ(hull->edge_directions.size(), 3u);
  for (const Vec3& vertex : hull->vertices) {
    EXPECT_DOUBLE_EQ(vertex.cwiseAbs().minCoeff(), 0.5);
  }
  EXPECT_NEAR(Volume(*hull), 1.0, 1e-12);
  testing::ExpectValidConvexPolyhedron(*hull, 1e-12);
}

TEST(ConvexHullTest, DuplicatedCornersGiveNoDuplicateVertices) {
  std::vector<Vec3> points;
  for (int copy = 0; copy < 3; ++copy) {
    for (int i = 0; i < 8; ++i) {
      points.emplace_back(i & 1 ? 2.0 : 1.0, i & 2 ? 0.5 : -0.5, i & 4 ? 3.0 : -3.0);
    }
  }
  const physics::Result<ConvexPolyhedron> hull = ComputeConvexHull(points);
  ASSERT_TRUE(hull.ok()) << hull.message();
  EXPECT_EQ(hull->vertices.size(), 8u);
  EXPECT_EQ(hull->faces.size(), 6u);
  EXPECT_NEAR(Volume(*hull), 1.0 * 1.0 * 6.0, 1e-12);
}

// Every point on a sphere is an extreme point of any set of sphere points,
// so all surface points must be hull vertices and no interior point may be.
TEST(ConvexHullTest, RandomCloudIsEnclosedAndVerticesAreInputPoints) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  constexpr int kSurfacePoints = 5000;
  constexpr int kInteriorPoints = 5000;
  std::vector<Vec3> points;
  for (int i = 0; i < kSurfacePoints; ++i) points.push_back(RandomUnitVector(random));
  for (int i = 0; i < kInteriorPoints; ++i) {
    // Radius 0.9 u^(1/3) is uniform in volume. The hull of the surface
    // points contains the ball of radius 0.9 unless a spherical cap of
    // angular radius acos(0.9), 5 % of the sphere, holds none of the 5000
    // surface points: probability 0.95^5000, nil.
    points.push_back(0.9 * std::cbrt(uniform(random)) * RandomUnitVector(random));
  }
  HullOptions options;
  options.max_vertices = 20000;
  const physics::Result<ConvexPolyhedron> hull = ComputeConvexHull(points, options);
  ASSERT_TRUE(hull.ok()) << hull.message();

  EXPECT_EQ(hull->vertices.size(), static_cast<size_t>(kSurfacePoints));
  const std::set<std::array<double, 3>> input = AsSet(points);
  for (const Vec3& vertex : hull->vertices) {
    EXPECT_EQ(input.count({vertex.x(), vertex.y(), vertex.z()}), 1u);
  }
  const double scale = 2.0;  // the cloud's diameter, m
  double worst_outside = -std::numeric_limits<double>::infinity();
  for (const Vec3& point : points) {
    for (const ConvexPolyhedron::Face& face : hull->faces) {
      worst_outside = std::max(worst_outside, face.normal.dot(point) - face.offset);
    }
  }
  EXPECT_LE(worst_outside, 1e-9 * scale);
  testing::ExpectValidConvexPolyhedron(*hull, 1e-9 * scale);
}

// An icosphere of 2562 vertices inscribed in the unit sphere: the volume
// deficit of an evenly spread inscribed polytope with n vertices is about
// sqrt(3) pi / n = 0.21 % (see HullOptions), and the inertia deficit, mass
// missing at radius 1, 5/3 of that, both inside the 1 % tolerance.
TEST(ConvexHullTest, TessellatedSphereHullMatchesAnalyticMassProperties) {
  const physics::TriangleMesh sphere = physics::testing::Icosphere(1.0, 4);
  ASSERT_EQ(sphere.vertices.size(), 2562u);
  HullOptions options;
  options.max_vertices = 4096;
  const physics::Result<ConvexPolyhedron> hull = ComputeConvexHull(sphere.vertices, options);
  ASSERT_TRUE(hull.ok()) << hull.message();
  EXPECT_EQ(hull->vertices.size(), 2562u);

  const double density = 1000.0;
  const physics::MassProperties mass = physics::PolyhedronMassProperties(density, *hull);
  const double volume = 4.0 / 3.0 * kPi;
  const double moment = 0.4 * density * volume;  // (2/5) m r^2 with r = 1
  EXPECT_NEAR(mass.mass / density, volume, 0.01 * volume);
  EXPECT_LT(mass.mass / density, volume);  // inscribed
  EXPECT_NEAR(mass.center_of_mass.norm(), 0.0, 1e-9);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(mass.inertia_about_com(i, i), moment, 0.01 * moment);
    for (int j = 0; j < 3; ++j) {
      if (i != j) {
        EXPECT_NEAR(mass.inertia_about_com(i, j), 0.0, 1e-6 * moment);
      }
    }
  }
}

// Simplifying 10,000 sphere points to n vertices loses at most 1.25 times
// the volume an inscribed polytope with n evenly spread vertices misses,
// sqrt(3) pi / n (see HullOptions), relative to the full hull.
TEST(ConvexHullTest, SimplificationKeepsAtMostMaxVerticesWithBoundedVolumeLoss) {
  std::mt19937_64 random(11);
  std::vector<Vec3> points;
  for (int i = 0; i < 10000; ++i) points.push_back(RandomUnitVector(random));
  HullOptions full_options;
  full_options.max_vertices = 20000;
  const physics::Result<ConvexPolyhedron> full = ComputeConvexHull(points, full_options);
  ASSERT_TRUE(full.ok()) << full.message();
  const double full_volume = Volume(*full);
  const std::set<std::array<double, 3>> input = AsSet(points);

  for (int max_vertices : {16, 64, 256}) {
    SCOPED_TRACE(max_vertices);
    HullOptions options;
    options.max_vertices = max_vertices;
    const physics::Result<ConvexPolyhedron> hull = ComputeConvexHull(points, options);
    ASSERT_TRUE(hull.ok()) << hull.message();
    EXPECT_LE(hull->vertices.size(), static_cast<size_t>(max_vertices));
    EXPECT_GE(hull->vertices.size(), static_cast<size_t>(0.9 * max_vertices));
    for (const Vec3& vertex : hull->vertices) {
      EXPECT_EQ(input.count({vertex.x(), vertex.y(), vertex.z()}), 1u);
    }
    const double loss = 1.0 - Volume(*hull) / full_volume;
    EXPECT_GT(loss, 0.0);
    EXPECT_LT(loss, 1.25 * std::sqrt(3.0) * kPi / max_vertices);
    testing::ExpectValidConvexPolyhedron(*hull, 1e-9);
  }
}

// A cylinder with 500 sides: 1000 hull vertices, but most lattice directions
// share supports, so the direction count must grow to use the budget.
TEST(ConvexHullTest, SimplificationOfFlatTopsUsesTheVertexBudget) {
  std::vector<Vec3> points;
  constexpr int kSides = 500;
  for (int i = 0; i < kSides; ++i) {
    const double angle = 2.0 * kPi * i / kSides;
    points.emplace_back(std::cos(angle), std::sin(angle), -0.5);
    points.emplace_back(std::cos(angle), std::sin(angle), 0.5);
  }
  const physics::Result<ConvexPolyhedron> hull = ComputeConvexHull(points);
  ASSERT_TRUE(hull.ok()) << hull.message();
  EXPECT_LE(hull->vertices.size(), 256u);
  EXPECT_GE(hull->vertices.size(), 200u);
  // A prism over a k-gon inscribed in the unit circle has volume
  // (k/2) sin(2 pi/k) * height; with k >= 100 sides it is within 0.07 % of pi.
  EXPECT_NEAR(Volume(*hull), kPi, 0.001 * kPi);
}

TEST(ConvexHullTest, RefusesDegenerateInputWithAClearMessage) {
  const std::vector<Vec3> three = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  physics::Result<ConvexPolyhedron> hull = ComputeConvexHull(three);
  ASSERT_FALSE(hull.ok());
  EXPECT_NE(hull.message().find("at least 4 points, got 3"), std::string::npos) << hull.message();

  std::vector<Vec3> with_nan = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  with_nan.emplace_back(std::nan(""), 0.0, 0.0);
  hull = ComputeConvexHull(with_nan);
  ASSERT_FALSE(hull.ok());
  EXPECT_NE(hull.message().find("point 4 is not finite"), std::string::npos) << hull.message();

  std::vector<Vec3> same(10, Vec3(1, 2, 3));
  hull = ComputeConvexHull(same);
  ASSERT_FALSE(hull.ok());
  EXPECT_NE(hull.message().find("coincide"), std::string::npos) << hull.message();

  std::vector<Vec3> line;
  for (int i = 0; i < 10; ++i) line.push_back(Vec3(1, 2, 3) * i);
  hull = ComputeConvexHull(line);
  ASSERT_FALSE(hull.ok());
  EXPECT_NE(hull.message().find("on a line"), std::string::npos) << hull.message();

  std::vector<Vec3> plate;
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Vec3 u = Vec3(1, 1, 0).normalized();
  const Vec3 v = Vec3(0, 0, 1);
  for (int i = 0; i < 100; ++i) plate.push_back(uniform(random) * u + uniform(random) * v);
  hull = ComputeConvexHull(plate);
  ASSERT_FALSE(hull.ok());
  EXPECT_NE(hull.message().find("in a plane"), std::string::npos) << hull.message();

  HullOptions too_few;
  too_few.max_vertices = 3;
  hull = ComputeConvexHull(physics::testing::BoxMesh(Vec3(1, 1, 1)).vertices, too_few);
  ASSERT_FALSE(hull.ok());
  EXPECT_NE(hull.message().find("max_vertices"), std::string::npos) << hull.message();
}

// A plate 1e-13 thick passes the degeneracy check when its tolerance is
// switched off; the hull must then be refused with a message, not abort.
// A 12 m square sheet of 50 x 50 points, flat but for single-precision
// round-off (1e-7 m of jitter, as in meshes exported from modelling tools),
// with one point in seven raised by up to 0.5 m. qhull's default merging
// leaves facets of the flat rim at angles near 1e-7 rad, and without the
// centrum pre-merge retry 50 of 60 such sheets had no valid hull. The
// hull must be the points' hull: its vertices input points, every point
// inside it, and its support in any direction that of the points.
TEST(ConvexHullTest, BumpySheetWithRoundOffHasItsHull) {
  constexpr int kSide = 50;
  constexpr double kHalfWidth = 6.0;  // m
  const double diagonal = std::sqrt(2.0 * 4.0 * kHalfWidth * kHalfWidth + 0.25);
  for (int seed = 0; seed < 5; ++seed) {
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<double> jitter(-0.5e-7, 0.5e-7);
    std::uniform_real_distribution<double> bump(0.0, 0.5);
    std::vector<Vec3> points;
    for (int i = 0; i < kSide; ++i) {
      for (int j = 0; j < kSide; ++j) {
        const bool inner = i > 0 && j > 0 && i < kSide - 1 && j < kSide - 1;
        const double z = inner && random() % 7 == 0 ? bump(random) : jitter(random);
        points.emplace_back(kHalfWidth * (2.0 * i / (kSide - 1) - 1.0) + jitter(random),
                            kHalfWidth * (2.0 * j / (kSide - 1) - 1.0) + jitter(random), z);
      }
    }
    HullOptions options;
    options.max_vertices = kSide * kSide;
    const physics::Result<ConvexPolyhedron> hull = ComputeConvexHull(points, options);
    ASSERT_TRUE(hull.ok()) << "seed " << seed << ": " << hull.message();

    const std::set<std::array<double, 3>> input = AsSet(points);
    for (const Vec3& vertex : hull->vertices) {
      EXPECT_EQ(input.count({vertex.x(), vertex.y(), vertex.z()}), 1u);
    }
    // The retry merges facets whose centrums are within 1e-6 of the
    // diagonal, so points may stand that far outside a merged facet.
    const double tolerance = 1e-6 * diagonal;
    double worst_outside = -std::numeric_limits<double>::infinity();
    for (const Vec3& point : points) {
      for (const ConvexPolyhedron::Face& face : hull->faces) {
        worst_outside = std::max(worst_outside, face.normal.dot(point) - face.offset);
      }
    }
    EXPECT_LE(worst_outside, tolerance) << "seed " << seed;
    for (int d = 0; d < 200; ++d) {
      const Vec3 direction = RandomUnitVector(random);
      double of_points = -std::numeric_limits<double>::infinity();
      for (const Vec3& point : points) of_points = std::max(of_points, direction.dot(point));
      double of_hull = -std::numeric_limits<double>::infinity();
      for (const Vec3& vertex : hull->vertices) of_hull = std::max(of_hull, direction.dot(vertex));
      EXPECT_NEAR(of_hull, of_points, tolerance) << "seed " << seed << ", direction " << d;
    }
    testing::ExpectValidConvexPolyhedron(*hull, 1e-7 * diagonal);
  }
}

// The node builds a hull again from the mesh helper's reply (its vertices
// and merged faces), so a hull must build from its own faces. These 16
// single-precision points spanning 1e-33 to 1e38 (found by
// mesh_parser_fuzzer) gave one whose merged face was degenerate against the
// second build's scale.
TEST(ConvexHullTest, HullBuildsAgainFromItsOwnFaces) {
  const std::vector<std::array<float, 3>> found = {
      {7.67283654e+34f, 4.7417776e+30f, 2.06998394e-19f},
      {1.71856889e+25f, 4.02739266e-11f, 1.10756849e+27f},
      {1.77510793e+28f, 7.26438006e+22f, 1.86155902e+34f},
      {8.48333114e-33f, 1.32919798e-14f, 7.68184349e+31f},
      {1.11282515e+27f, 2.0699842e-19f, 4.75449973e+30f},
      {4.54451143e+30f, 1.89454763e+23f, 7.14432799e+31f},
      {1.7142145e+29f, 7.09639849e+22f, 2.11296489e-19f},
      {2.76036423e+20f, 1.20431659e-32f, 4.43769426e+27f},
      {2.07041304e-19f, 6.71108672e+22f, 1.71102294e+29f},
      {7.09639849e+22f, 1.01546096e-08f, 6.29828023e-10f},
      {6.63817332e-07f, 6.3369221e-10f, 8.72427663e-33f},
      {8.45697633e+37f, 8.4570174e+37f, 1.01391588e-08f},
      {4.00463725e-11f, 1.53479033e-19f, 6.33692931e-10f},
      {8.72427663e-33f, 1.01390869e-08f, 4.00463725e-11f},
      {1.53479033e-19f, 2.62529284e-06f, 5.02797026e-10f},
      {1.53478994e-19f, 2.53477173e-09f, 9.10675875e-12f},
  };
  std::vector<Vec3> points;
  for (const std::array<float, 3>& p : found) points.emplace_back(p[0], p[1], p[2]);
  const physics::Result<ConvexPolyhedron> hull = ComputeConvexHull(points);
  ASSERT_TRUE(hull.ok()) << hull.message();
  std::vector<std::vector<int>> faces;
  for (int face = 0; face < static_cast<int>(hull->faces.size()); ++face) {
    faces.push_back(hull->FaceVertices(face));
  }
  const physics::Result<ConvexPolyhedron> again =
      physics::MakeConvexPolyhedron(hull->vertices, faces);
  ASSERT_TRUE(again.ok()) << again.message();
  EXPECT_EQ(again->vertices, hull->vertices);
}

TEST(ConvexHullTest, QhullPrecisionFailureIsReportedNotRaised) {
  std::vector<Vec3> plate;
  for (int i = 0; i < 8; ++i) {
    plate.emplace_back(i & 1 ? 1.0 : 0.0, i & 2 ? 1.0 : 0.0, i & 4 ? 1e-13 : 0.0);
  }
  HullOptions options;
  options.degenerate_tolerance = 0.0;
  const physics::Result<ConvexPolyhedron> hull = ComputeConvexHull(plate, options);
  ASSERT_FALSE(hull.ok());
  EXPECT_NE(hull.message().find("convex hull"), std::string::npos) << hull.message();
}

}  // namespace
}  // namespace rigid_body_sim::io
