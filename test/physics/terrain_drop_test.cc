// Boxes dropped on a static triangle-mesh terrain (issue 39, item 2): none
// sinks through it, slow or fast, and all come to rest on it.
//
// How deep a corner may go, from the solver's rules. A point of a pair that
// already touches elsewhere is the resting solver's only once it touches
// itself, and the time-of-impact search leaves such a pair alone unless its
// body is fast. A body that is not fast moves no point by more than
// continuous_fraction of its thickness in a step (BoundBodyMotion), so a
// corner swung down by the spin of a corner impact can end a step at most
// that deep, 0.25 x 0.1 m = 25 mm for these boxes, before the solver holds
// it and the split impulse lifts it out; a fast body's samples are that far
// apart. The same drops on the flat half-space reach 10.1 mm
// (FlatGroundAllowsAStepOfMotion). At rest, the split impulse leaves
// penetration_slop, less 20 % of the excess per step: after the
// time_to_sleep of quiet steps before a body sleeps, 0.8^120 of at most
// 25 mm, 6e-14 m. A box's depths are measured vertically, under each
// corner: a depth d along a normal tilted by theta is d / cos(theta) below
// the surface.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "mesh_fixtures_static.h"
#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/world.h"
#include "scene.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::AddGround;
using testing::AddSphere;
using testing::BoxSpec;
using testing::MakeMaterial;
using testing::SphereSpec;
using testing::Translation;

// The terrain: a 10 m square of 224 x 224 cells (100,352 triangles) over
// z = A (sin(2 pi x / L_x) + sin(2 pi y / L_y)), hills of +-2A = +-5 cm.
constexpr int kCells = 224;
constexpr double kSide = 10.0;  // m
constexpr double kCell = kSide / kCells;
constexpr double kOrigin = -0.5 * kSide;
constexpr double kAmplitude = 0.025;  // m, A, of each wave
constexpr double kWaveX = 2.5;        // m
constexpr double kWaveY = 1.6;        // m
// The half-space under everything, as in the node's scene.
constexpr double kGroundZ = -0.5;  // m

constexpr double kEdge = 0.1;  // m
constexpr double kMass = 0.5;  // kg
constexpr double kFriction = 0.6;

double Hills(double x, double y) {
  return kAmplitude * (std::sin(2.0 * M_PI * x / kWaveX) + std::sin(2.0 * M_PI * y / kWaveY));
}

// cos of the steepest slope. The height is a sum of a function of x and
// one of y, so a triangle's gradient (divided differences along x and y)
// is at most (max |h_x|, max |h_y|) = 2 pi A (1 / L_x, 1 / L_y): 6.65
// degrees.
double SteepestCosine() {
  const double gradient = 2.0 * M_PI * kAmplitude * std::hypot(1.0 / kWaveX, 1.0 / kWaveY);
  return 1.0 / std::sqrt(1.0 + gradient * gradient);
}

// The height of the triangulated surface at (x, y): the linear interpolant
// of Hills over MakeGrid's triangle of the cell, (i, j)-(i+1, j)-(i+1, j+1)
// below the diagonal, (i, j)-(i+1, j+1)-(i, j+1) above it. It is the surface
// the bodies meet; Hills lies up to |h''| cell^2 / 8 = 0.1 mm above it on
// the hilltops.
double SurfaceHeight(double x, double y) {
  const double u = std::clamp((x - kOrigin) / kCell, 0.0, kCells - 1e-9);
  const double v = std::clamp((y - kOrigin) / kCell, 0.0, kCells - 1e-9);
  const int i = static_cast<int>(std::floor(u));
  const int j = static_cast<int>(std::floor(v));
  const double fx = u - i;
  const double fy = v - j;
  const auto h = [](int a, int b) { return Hills(kOrigin + a * kCell, kOrigin + b * kCell); };
  if (fx >= fy)
    return h(i, j) + fx * (h(i + 1, j) - h(i, j)) + fy * (h(i + 1, j + 1) - h(i + 1, j));
  return h(i, j) + fy * (h(i, j + 1) - h(i, j)) + fx * (h(i + 1, j + 1) - h(i, j + 1));
}

bool OverTerrain(const Vec3& point) {
  return std::abs(point.x()) < 0.5 * kSide && std::abs(point.y()) < 0.5 * kSide;
}

const std::shared_ptr<const CollisionMesh>& Terrain() {
  static const std::shared_ptr<const CollisionMesh> mesh =
      testing::Build(testing::MakeGrid(kOrigin, kOrigin, kCell, kCells, kCells, Hills));
  return mesh;
}

// The terrain and the half-space under it; `flat`: the half-space z <= 0
// alone, the flat ground to compare with.
void AddScenery(bool flat, World* world) {
  const Material material = MakeMaterial(kFriction, 0.0);
  if (flat) {
    AddGround(world, material);
    return;
  }
  BodyDef def;
  def.is_static = true;
  ShapeDef shape;
  shape.geometry = StaticMesh{Terrain()};
  shape.material = material;
  def.shapes.push_back(shape);
  ASSERT_TRUE(world->CreateBody(def).ok());
  AddGround(world, material, Translation(0.0, 0.0, kGroundZ));
}

// The least height of a box's corners above the surface under each, m.
double LowestCornerAbove(bool flat, const Pose& world_from_box) {
  double lowest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner =
        world_from_box *
        (0.5 * kEdge * Vec3(k & 1 ? 1.0 : -1.0, k & 2 ? 1.0 : -1.0, k & 4 ? 1.0 : -1.0));
    lowest = std::min(lowest, corner.z() - (flat ? 0.0 : SurfaceHeight(corner.x(), corner.y())));
  }
  return lowest;
}

BoxSpec MakeBoxSpec() {
  BoxSpec spec;
  spec.size = Vec3::Constant(kEdge);
  spec.mass = kMass;
  spec.material = MakeMaterial(kFriction, 0.0);
  return spec;
}

struct DropStats {
  double deepest = std::numeric_limits<double>::infinity();  // m, least LowestCornerAbove
  int deepest_box = -1;
  int deepest_step = -1;
  int sunk = 0;  // boxes ending more than 1 cm below the surface
  double lowest_end = std::numeric_limits<double>::infinity();  // m, LowestCornerAbove at the end
  double highest_end = -std::numeric_limits<double>::infinity();
  int awake_end = 0;
  double fastest_end = 0.0;   // m/s, of the boxes awake at the end
  double fastest_spin = 0.0;  // rad/s, likewise
};

// One batch: per_side^2 boxes, one per cell of a grid over the square (so
// that they fall apart), each somewhere in the middle half of its cell,
// turned at random, spinning at about 5 rad/s per axis and dropped from
// 5-50 cm above the surface (its lowest point); stepped for `steps`.
void DropBatch(bool flat, int per_side, int steps, int first_box, std::mt19937* random,
               DropStats* stats) {
  World world;
  AddScenery(flat, &world);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<BodyId> boxes;
  const double spacing = (kSide - 0.4) / per_side;
  for (int j = 0; j < per_side; ++j) {
    for (int i = 0; i < per_side; ++i) {
      BoxSpec spec = MakeBoxSpec();
      const double x = kOrigin + 0.2 + spacing * (i + 0.25 + 0.5 * unit(*random));
      const double y = kOrigin + 0.2 + spacing * (j + 0.25 + 0.5 * unit(*random));
      const double drop = 0.05 + 0.45 * unit(*random);
      // Clear of the surface: no corner is further than sqrt(3)/2 edge from
      // the centre.
      spec.world_from_body =
          Translation(x, y, (flat ? 0.0 : Hills(x, y)) + 0.5 * std::sqrt(3.0) * kEdge + drop);
      spec.world_from_body.rotation =
          Quat(Eigen::Vector4d(normal(*random), normal(*random), normal(*random), normal(*random))
                   .normalized());
      spec.angular_velocity = 5.0 * Vec3(normal(*random), normal(*random), normal(*random));
      boxes.push_back(AddBox(&world, spec));
    }
  }
  for (int step = 0; step < steps; ++step) {
    world.Step();
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      const double above = LowestCornerAbove(flat, world.GetPose(boxes[b]));
      if (above < stats->deepest) {
        stats->deepest = above;
        stats->deepest_box = first_box + static_cast<int>(b);
        stats->deepest_step = step;
      }
    }
  }
  for (std::size_t b = 0; b < boxes.size(); ++b) {
    const BodyId id = boxes[b];
    const Body& body = world.GetBody(id);
    const double above = LowestCornerAbove(flat, body.WorldFromBody());
    stats->sunk += above < -0.01;
    stats->lowest_end = std::min(stats->lowest_end, above);
    stats->highest_end = std::max(stats->highest_end, above);
    if (!body.awake) continue;
    ++stats->awake_end;
    stats->fastest_end = std::max(stats->fastest_end, body.linear_velocity.norm());
    stats->fastest_spin = std::max(stats->fastest_spin, body.angular_velocity.norm());
  }
}

DropStats DropBoxes(bool flat, int batches, int per_side, int steps) {
  std::mt19937 random(39);
  DropStats stats;
  for (int batch = 0; batch < batches; ++batch) {
    DropBatch(flat, per_side, steps, batch * per_side * per_side, &random, &stats);
  }
  std::printf(
      "%s: deepest corner %+.6f m (box %d, step %d), %d sunk; after %.1f s the lowest corners "
      "%+.6f to %+.6f m above the surface, %d awake (at most %.4f m/s, %.4f rad/s)\n",
      flat ? "flat ground" : "terrain", stats.deepest, stats.deepest_box, stats.deepest_step,
      stats.sunk, steps * WorldSettings().time_step, stats.lowest_end, stats.highest_end,
      stats.awake_end, stats.fastest_end, stats.fastest_spin);
  return stats;
}

// m: the motion a body that is not fast makes in a step at most, so the
// deepest a corner not yet touching can end a step (see the top).
double StepMotionAllowance() { return WorldSettings().continuous_fraction * kEdge; }

// m: the penetration a resting contact keeps, the slop and the excess the
// split impulse has not yet removed when the body falls asleep.
double RestAllowance() {
  const WorldSettings settings;
  const double quiet_steps = settings.sleep.time_to_sleep / settings.time_step;
  return settings.solver.penetration_slop +
         std::pow(1.0 - settings.solver.position_correction, quiet_steps) * StepMotionAllowance();
}

// m: how far the triangulated hills can rise above the plane of a box face
// resting on them where no contact point holds it. The manifold keeps four
// points of the face (the deepest, then the widest spread), and between
// them the surface departs from the plane through them as from a linear
// interpolant: by at most M R^2 / 2 for a second directional derivative
// bounded by M over a simplex in a ball of radius R (Waldron 1998, "The
// error in linear interpolation at the vertices of a simplex", SIAM J.
// Numer. Anal. 35(3), theorem 1), R = half the face's diagonal; the
// triangles depart from the hills by the same bound with R half a cell's
// diagonal. M = (2 pi)^2 A max(1 / L_x^2, 1 / L_y^2) = 0.39 / m: 1.16 mm.
double CurvatureAllowance() {
  const double m = std::pow(2.0 * M_PI, 2) * kAmplitude / std::pow(std::min(kWaveX, kWaveY), 2);
  const double face = 0.5 * std::sqrt(2.0) * kEdge;
  const double cell = 0.5 * std::sqrt(2.0) * kCell;
  return 0.5 * m * (face * face + cell * cell);
}

// The resting allowance and the bound on the motion within a step, on the
// half-space: the numbers the terrain is held to. With the seed of the
// terrain test, the deepest corner is 10.1 mm (box 1, step 79, swung down
// by the spin a corner impact gave it), and the boxes rest 1e-4 m deep,
// 4.9e-14 m more at most.
TEST(TerrainDropTest, FlatGroundAllowsAStepOfMotion) {
  const DropStats flat = DropBoxes(/*flat=*/true, 10, 10, 5 * 240);
  EXPECT_EQ(flat.sunk, 0);
  EXPECT_GE(flat.deepest, -StepMotionAllowance());
  EXPECT_GE(flat.lowest_end, -RestAllowance());
  EXPECT_LE(flat.highest_end, 0.005);
  EXPECT_EQ(flat.awake_end, 0);
}

// 1,000 boxes (10 cm, 0.5 kg, mu 0.6) dropped onto 100,352 triangles of
// hills, in batches of 100. Before the fix 59 of them passed through the
// terrain at 2.4-3.4 m/s and ended on the half-space 0.5 m below (deepest
// corner 0.499 m under the surface, box 127; it went through at step 70: a
// corner 1.1 cm into triangles of 4.5 cm cells met every prism on a side
// axis, and every contact was dropped as an internal edge's), 32 were still
// awake after 5 s, and 495 rested with a corner more than the slop below
// the surface, down to 9.2 mm. Now: deepest 12.1 mm in a step (box 830,
// swung down by a corner impact, as on flat ground), none sunk, all asleep,
// the lowest corners 0.38 mm below to 0.46 mm above the surface at the
// end.
TEST(TerrainDropTest, ThousandBoxesLandAndRestOnTerrain) {
  const double cosine = SteepestCosine();
  const DropStats terrain = DropBoxes(/*flat=*/false, 10, 10, 5 * 240);
  EXPECT_EQ(terrain.sunk, 0);
  EXPECT_GE(terrain.deepest, -StepMotionAllowance() / cosine);
  // At rest on the surface: no deeper than the flat ground's allowance and
  // the curvature under the face, no higher than 5 mm, and asleep or slower
  // than the sleep thresholds.
  EXPECT_GE(terrain.lowest_end, -(RestAllowance() / cosine + CurvatureAllowance()));
  EXPECT_LE(terrain.highest_end, 0.005);
  EXPECT_LT(terrain.fastest_end, WorldSettings().sleep.linear_velocity);
  EXPECT_LT(terrain.fastest_spin, WorldSettings().sleep.angular_velocity);
}

// The distance from p to the triangulated surface, m, negative below it:
// the nearest of the triangles of the 5 x 5 cells about p (closest point
// on a triangle by its Voronoi regions, Ericson 2005, "Real-Time Collision
// Detection", section 5.1.5).
double SignedDistanceToSurface(const Vec3& p) {
  const auto closest = [&p](const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0.0 && d2 <= 0.0) return a;
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0.0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return Vec3(a + d1 / (d1 - d3) * ab);
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0.0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return Vec3(a + d2 / (d2 - d6) * ac);
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
      return Vec3(b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b));
    }
    const double denominator = 1.0 / (va + vb + vc);
    return Vec3(a + ab * vb * denominator + ac * vc * denominator);
  };
  const auto vertex = [](int i, int j) {
    const double x = kOrigin + i * kCell;
    const double y = kOrigin + j * kCell;
    return Vec3(x, y, Hills(x, y));
  };
  const int i0 = static_cast<int>(std::floor((p.x() - kOrigin) / kCell));
  const int j0 = static_cast<int>(std::floor((p.y() - kOrigin) / kCell));
  double nearest = std::numeric_limits<double>::infinity();
  for (int j = std::max(0, j0 - 2); j <= std::min(kCells - 1, j0 + 2); ++j) {
    for (int i = std::max(0, i0 - 2); i <= std::min(kCells - 1, i0 + 2); ++i) {
      nearest = std::min(
          nearest, (p - closest(vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1))).norm());
      nearest = std::min(
          nearest, (p - closest(vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1))).norm());
    }
  }
  return p.z() >= SurfaceHeight(p.x(), p.y()) ? nearest : -nearest;
}

// Boxes and balls fired down at the terrain at 50 m/s (0.21 m a step, two
// edges of a box), straight down to 30 degrees off, the boxes tumbling,
// from 0.5 m above it. While over the terrain (a ball rolls off it, a box
// may bounce off its edge) no corner, no point of a ball, goes deeper than
// a fast body's sample allows (see the top), and each shot ends above the
// surface by that bound or leaves the terrain above it. Before the fix a
// box (shot 10, 8.2 degrees off vertical) went through and ended 0.27 m
// under the surface, and another's corner went 23 mm deep (shot 8).
TEST(TerrainDropTest, FiftyMetresPerSecondStopsAtTerrain) {
  constexpr int kShots = 12;
  constexpr double kSpeed = 50.0;   // m/s
  constexpr double kRadius = 0.05;  // m, of the balls
  const double allowance = StepMotionAllowance() / SteepestCosine();
  std::mt19937 random(50);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int shot = 0; shot < kShots; ++shot) {
    const bool ball = shot % 2 == 1;
    World world;
    AddScenery(/*flat=*/false, &world);
    const double x = -2.0 + 4.0 * unit(random);
    const double y = -2.0 + 4.0 * unit(random);
    const double tilt = M_PI / 6.0 * unit(random);
    const double heading = 2.0 * M_PI * unit(random);
    const Vec3 velocity = kSpeed * Vec3(std::sin(tilt) * std::cos(heading),
                                        std::sin(tilt) * std::sin(heading), -std::cos(tilt));
    const Pose start = Translation(x, y, Hills(x, y) + 0.5);
    BodyId id;
    if (ball) {
      SphereSpec spec;
      spec.radius = kRadius;
      spec.mass = kMass;
      spec.world_from_body = start;
      spec.linear_velocity = velocity;
      spec.material = MakeMaterial(kFriction, 0.0);
      id = AddSphere(&world, spec);
    } else {
      BoxSpec spec = MakeBoxSpec();
      spec.world_from_body = start;
      spec.world_from_body.rotation =
          Quat(Eigen::Vector4d(normal(random), normal(random), normal(random), normal(random))
                   .normalized());
      spec.linear_velocity = velocity;
      spec.angular_velocity = 10.0 * Vec3(normal(random), normal(random), normal(random));
      id = AddBox(&world, spec);
    }
    const auto above = [&] {
      const Pose pose = world.GetPose(id);
      return ball ? SignedDistanceToSurface(pose.translation) - kRadius
                  : LowestCornerAbove(/*flat=*/false, pose);
    };
    double deepest = std::numeric_limits<double>::infinity();
    double last = 0.0;     // m, above the surface at the last step over it
    bool stopped = false;  // whether the terrain took its downward speed
    int steps = 0;
    for (; steps < 240; ++steps) {
      world.Step();
      if (!OverTerrain(world.GetPose(id).translation)) break;
      last = above();
      deepest = std::min(deepest, last);
      stopped = stopped || world.GetLinearVelocity(id).z() >= 0.0;
    }
    std::printf(
        "shot %2d (%s, %4.1f degrees off vertical): deepest %+.6f m, %+.6f m above the surface "
        "after %d steps%s\n",
        shot, ball ? "ball" : "box ", tilt * 180.0 / M_PI, deepest, last, steps,
        steps < 240 ? ", then off the terrain" : "");
    EXPECT_TRUE(stopped) << "shot " << shot;
    EXPECT_GE(deepest, -allowance) << "shot " << shot;
    EXPECT_GE(last, -allowance) << "shot " << shot;
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics
