#include "rigid_body_sim/io/convex_decomposition.h"

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "concave_meshes.h"
#include "polyhedron_checks.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"

namespace rigid_body_sim::io {
namespace {

using physics::ConvexPolyhedron;
using physics::Vec3;

double Volume(const ConvexPolyhedron& polyhedron) {
  return physics::PolyhedronMassProperties(1.0, polyhedron).mass;
}

double TotalVolume(const std::vector<ConvexPolyhedron>& pieces) {
  double total = 0.0;
  for (const ConvexPolyhedron& piece : pieces) total += Volume(piece);
  return total;
}

// Inside or on the boundary: below every face plane.
bool Contains(const ConvexPolyhedron& piece, const Vec3& point) {
  for (const ConvexPolyhedron::Face& face : piece.faces) {
    if (face.normal.dot(point) > face.offset) return false;
  }
  return true;
}

TEST(ConvexDecompositionTest, BoxIsOnePieceEqualToItself) {
  const physics::TriangleMesh box = testing::BoxMesh(Vec3(-0.1, -0.2, 0.0), Vec3(0.13, 0.2, 0.07));
  for (const PiecesRule rule : {PiecesRule::kAuto, PiecesRule::kAlways}) {
    const auto pieces = ConvexPieces(box, DecompositionOptions{}, rule);
    ASSERT_TRUE(pieces.ok()) << pieces.message();
    ASSERT_EQ(pieces->size(), 1u);
    EXPECT_NEAR(Volume(pieces->front()), 0.23 * 0.4 * 0.07, 1e-12);
    EXPECT_EQ(pieces->front().vertices.size(), 8u);
    testing::ExpectValidConvexPolyhedron(pieces->front(), 1e-12);
  }
}

TEST(ConvexDecompositionTest, LShapeSplitsIntoItsTwoLegs) {
  // Legs 0.3 m long and 0.05 m thick, 0.1 m deep: volume 0.1 * (0.3 * 0.05
  // + 0.05 * 0.25) = 2.75e-3 m^3; its hull adds the triangle between the
  // legs, 0.1 * 0.25 * 0.25 / 2 = 3.125e-3 m^3, more than doubling it.
  const physics::TriangleMesh l_shape = testing::LPrism(0.3, 0.3, 0.05, 0.1);
  const double volume = 2.75e-3;
  const auto hull = ComputeConvexHull(l_shape.vertices);
  ASSERT_TRUE(hull.ok());
  EXPECT_NEAR(Volume(*hull), volume + 3.125e-3, 1e-12);

  const auto pieces = ConvexPieces(l_shape, DecompositionOptions{}, PiecesRule::kAuto);
  ASSERT_TRUE(pieces.ok()) << pieces.message();
  EXPECT_GE(pieces->size(), 2u);
  EXPECT_LE(pieces->size(), 4u);
  // The pieces cover the L; each hull exceeds its part by at most
  // max_concavity (1 %) of the L's volume.
  EXPECT_GE(TotalVolume(*pieces), volume * (1.0 - 1e-9));
  EXPECT_LE(TotalVolume(*pieces), volume * (1.0 + 0.01 * pieces->size()));
  // The empty corner between the legs (the hull's) is in no piece.
  for (const ConvexPolyhedron& piece : *pieces) {
    testing::ExpectValidConvexPolyhedron(piece, 1e-9);
    EXPECT_FALSE(Contains(piece, Vec3(0.15, 0.05, 0.15)));
    EXPECT_FALSE(Contains(piece, Vec3(0.08, 0.05, 0.08)));
  }
}

TEST(ConvexDecompositionTest, CupPiecesLeaveTheCavityOpen) {
  // Outer radius 4 cm, inner 3.5 cm, 10 cm tall, a 1 cm floor, 32 segments.
  const int segments = 32;
  const physics::TriangleMesh cup = testing::Cup(0.04, 0.035, 0.10, 0.01, segments);
  const double volume =
      testing::PolygonArea(0.04, segments) * 0.10 - testing::PolygonArea(0.035, segments) * 0.09;
  const auto start = std::chrono::steady_clock::now();
  const auto pieces = ConvexPieces(cup, DecompositionOptions{}, PiecesRule::kAuto);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(pieces.ok()) << pieces.message();
  std::printf("cup: %zu pieces, volume %.4g of %.4g, %.3f s\n", pieces->size(),
              TotalVolume(*pieces), volume, seconds);
  EXPECT_GE(pieces->size(), 4u);
  EXPECT_GE(TotalVolume(*pieces), volume * (1.0 - 1e-9));
  // Every piece's hull exceeds its part by at most max_concavity (1 %) of
  // the cup's volume, and merging keeps that bound.
  EXPECT_LE(TotalVolume(*pieces), volume * (1.0 + 0.01 * pieces->size()));
  // A 2 cm ball resting on the floor, centred: every point of it within
  // 1 mm of the floor and up to the rim is in no piece.
  for (const ConvexPolyhedron& piece : *pieces) {
    testing::ExpectValidConvexPolyhedron(piece, 1e-9);
    for (double z = 0.011; z <= 0.10; z += 0.005) {
      for (int i = 0; i < 16; ++i) {
        const double angle = 2.0 * M_PI * i / 16;
        for (const double radius : {0.0, 0.005, 0.01, 0.015}) {
          const Vec3 point(radius * std::cos(angle), radius * std::sin(angle), z);
          EXPECT_FALSE(Contains(piece, point)) << point.transpose();
        }
      }
    }
  }
}

// The sample points of a cavity farther than `wall` from its walls (a grid
// of `step`) that lie inside some piece: none, for pieces that keep the
// cavity open.
int CoveredCavityPoints(const std::vector<ConvexPolyhedron>& pieces,
                        const std::vector<Vec3>& cavity) {
  int covered = 0;
  for (const Vec3& point : cavity) {
    for (const ConvexPolyhedron& piece : pieces) {
      if (Contains(piece, point)) {
        ++covered;
        break;
      }
    }
  }
  return covered;
}

std::vector<Vec3> GridPoints(const Vec3& lower, const Vec3& upper, double step,
                             const std::function<bool(const Vec3&)>& keep) {
  std::vector<Vec3> points;
  for (double x = lower.x(); x <= upper.x(); x += step) {
    for (double y = lower.y(); y <= upper.y(); y += step) {
      for (double z = lower.z(); z <= upper.z(); z += step) {
        if (keep(Vec3(x, y, z))) points.emplace_back(x, y, z);
      }
    }
  }
  return points;
}

// A mug 8 cm wide, 10 cm tall, with 4 mm walls and a 5 mm floor, 32
// segments; its volume is 0.23 of its hull's. And a hemispherical bowl 12 cm
// wide with 3 mm walls. Every point of the cavity more than one wall
// thickness from the walls, up to the rim, lies in no piece; the pieces
// still cover the part.
TEST(ConvexDecompositionTest, ThinWalledPartsKeepTheirCavityOpen) {
  struct Part {
    const char* name;
    physics::TriangleMesh mesh;
    std::vector<Vec3> cavity;
  };
  const double step = 0.002;
  std::vector<Part> parts;
  parts.push_back(
      {"mug", testing::Cup(0.04, 0.036, 0.10, 0.005, 32),
       GridPoints(Vec3(-0.04, -0.04, 0.0), Vec3(0.04, 0.04, 0.10), step, [](const Vec3& p) {
         return p.head<2>().norm() <= 0.036 - 0.004 && p.z() >= 0.009;
       })});
  parts.push_back(
      {"bowl", testing::Bowl(0.06, 0.003, 16, 32),
       GridPoints(Vec3(-0.06, -0.06, 0.0), Vec3(0.06, 0.06, 0.06), step,
                  [](const Vec3& p) { return (p - Vec3(0, 0, 0.06)).norm() <= 0.057 - 0.003; })});
  // The mug again with ten rings up its walls, and moved off the origin and
  // turned off the grid's axes: its cavity stays open however it is
  // tessellated and placed.
  std::vector<std::array<double, 2>> profile = {{0.0, 0.0}};
  for (int k = 0; k <= 10; ++k) profile.push_back({0.04, 0.01 * k});
  for (int k = 10; k >= 0; --k) profile.push_back({0.036, 0.005 + 0.0095 * k});
  profile.push_back({0.0, 0.005});
  parts.push_back({"mug_rings", testing::Revolve(profile, 32), parts[0].cavity});
  const Eigen::Isometry3d moved =
      Eigen::Translation3d(0.013, -0.021, 0.0) * Eigen::AngleAxisd(0.3, Vec3::UnitZ());
  Part shifted{"mug_moved", parts[0].mesh, parts[0].cavity};
  for (Vec3& vertex : shifted.mesh.vertices) vertex = moved * vertex;
  for (Vec3& point : shifted.cavity) point = moved * point;
  parts.push_back(std::move(shifted));
  for (const Part& part : parts) {
    const auto mass = physics::TriangleMeshMassProperties(1.0, part.mesh);
    ASSERT_TRUE(mass.ok()) << part.name << ": " << mass.message();
    const auto start = std::chrono::steady_clock::now();
    const auto pieces = ConvexPieces(part.mesh, DecompositionOptions{}, PiecesRule::kAuto);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(pieces.ok()) << pieces.message();
    const int covered = CoveredCavityPoints(*pieces, part.cavity);
    std::printf(
        "%s (%zu triangles): %zu pieces, %.4g m^3 of %.4g m^3, %d of %zu cavity points "
        "covered, %.3f s\n",
        part.name, part.mesh.triangles.size(), pieces->size(), TotalVolume(*pieces), mass->mass,
        covered, part.cavity.size(), seconds);
    EXPECT_EQ(covered, 0) << part.name;
    EXPECT_GE(TotalVolume(*pieces), mass->mass * (1.0 - 1e-9)) << part.name;
    for (const ConvexPolyhedron& piece : *pieces) testing::ExpectValidConvexPolyhedron(piece, 1e-9);
  }
}

TEST(ConvexDecompositionTest, OpenMeshIsRefusedOrHulled) {
  physics::TriangleMesh open = testing::LPrism(0.3, 0.3, 0.05, 0.1);
  open.triangles.pop_back();
  const auto refused = ConvexPieces(open, DecompositionOptions{}, PiecesRule::kAlways);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("closed"), std::string::npos) << refused.message();
  const auto hulled = ConvexPieces(open, DecompositionOptions{}, PiecesRule::kAuto);
  ASSERT_TRUE(hulled.ok()) << hulled.message();
  EXPECT_EQ(hulled->size(), 1u);
}

TEST(ConvexDecompositionTest, OptionsOutOfRangeAreNamed) {
  DecompositionOptions options;
  options.max_pieces = 0;
  const physics::Status status = CheckDecompositionOptions(options);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("max_pieces 0"), std::string::npos) << status.message();
  options = DecompositionOptions{};
  options.max_concavity = 0.0;
  EXPECT_FALSE(CheckDecompositionOptions(options).ok());
}

}  // namespace
}  // namespace rigid_body_sim::io
