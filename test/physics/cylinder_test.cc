// Exact cylinders: closed-form contact geometry against half-spaces, spheres
// and boxes, distances against GJK on a fine prism, and rolling and standing
// on inclines against the rigid-body closed forms.
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "physics/collision/narrow_phase.h"
#include "scene.h"
#include "support/gjk.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::AddGround;
using testing::BoxSpec;
using testing::MakeMaterial;

constexpr double kExact = 1e-9;  // m: exact geometry up to rounding
constexpr double kG = 9.81;      // m/s^2
constexpr double kDegree = kPi / 180.0;

Quat AxisAngle(double angle, const Vec3& axis) {
  return Quat(Eigen::AngleAxisd(angle, axis.normalized()));
}

ContactManifold CollideShapes(const ShapeGeometry& a, const Pose& world_from_a,
                              const ShapeGeometry& b, const Pose& world_from_b,
                              double contact_distance = 0.0) {
  ContactManifold manifold;
  Collide({&a, world_from_a, &b, world_from_b, contact_distance}, nullptr, &manifold);
  return manifold;
}

double DeepestSeparation(const ContactManifold& manifold) {
  double deepest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < manifold.point_count; ++i) {
    deepest = std::min(deepest, manifold.points[i].separation);
  }
  return deepest;
}

TEST(CylinderGeometryTest, SupportAndClosestPointAreClosedForms) {
  const Cylinder cylinder{0.3, 0.5};
  const Vec3 support = CylinderSupport(cylinder, Vec3(3, 4, -1));
  EXPECT_LE((support - Vec3(0.18, 0.24, -0.5)).norm(), kExact);
  EXPECT_LE((ClosestPointOnCylinder(cylinder, Vec3(0, 0.9, 0.7)) - Vec3(0, 0.3, 0.5)).norm(),
            kExact);
  EXPECT_LE((ClosestPointOnCylinder(cylinder, Vec3(0.1, 0, 0.2)) - Vec3(0.1, 0, 0.2)).norm(),
            kExact);
}

// Standing on its cap, sunk by d: every point of the rim octagon is d deep;
// four are kept, all at radius r from the axis.
TEST(CylinderHalfSpaceTest, StandingOnItsCapGivesFourRimPointsAtTheSinkDepth) {
  const ShapeGeometry cylinder = Cylinder{0.2, 0.4};
  const double sink = 1e-3;
  const Pose world_from_cylinder{Vec3(1, 2, 0.4 - sink), Quat::Identity()};
  const ContactManifold manifold =
      CollideShapes(cylinder, world_from_cylinder, HalfSpace{}, Pose::Identity());
  ASSERT_EQ(manifold.point_count, 4);
  EXPECT_LE((manifold.normal_world - Vec3::UnitZ()).norm(), kExact);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(manifold.points[i].separation, -sink, kExact);
    const Vec3 radial = manifold.points[i].position_world - Vec3(1, 2, 0);
    EXPECT_NEAR(radial.head<2>().norm(), 0.2, kExact);
  }
}

// Lying on its side (axis horizontal): two points, at the two ends of the
// lowest line, each at depth d.
TEST(CylinderHalfSpaceTest, LyingOnItsSideGivesTheEndsOfTheLowestLine) {
  const ShapeGeometry cylinder = Cylinder{0.2, 0.4};
  const double sink = 2e-3;
  const Pose world_from_cylinder{Vec3(0, 0, 0.2 - sink), AxisAngle(kPi / 2, Vec3::UnitX())};
  const ContactManifold manifold =
      CollideShapes(cylinder, world_from_cylinder, HalfSpace{}, Pose::Identity());
  ASSERT_EQ(manifold.point_count, 2);
  std::vector<double> ends;
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(manifold.points[i].separation, -sink, kExact);
    EXPECT_NEAR(manifold.points[i].position_world.x(), 0.0, kExact);
    ends.push_back(manifold.points[i].position_world.y());
  }
  EXPECT_NEAR(std::abs(ends[0] - ends[1]), 0.8, kExact);
}

// Tilted by any angle, the deepest point is the support in -n:
// z_c - h |cos| - r |sin|.
TEST(CylinderHalfSpaceTest, TiltedCylinderDeepestPointIsItsSupport) {
  const ShapeGeometry cylinder = Cylinder{0.15, 0.35};
  for (double tilt : {0.1, 0.5, 1.0, 1.4}) {
    SCOPED_TRACE(tilt);
    const double height = 0.35 * std::cos(tilt) + 0.15 * std::sin(tilt) - 0.004;
    const Pose world_from_cylinder{Vec3(0, 0, height), AxisAngle(tilt, Vec3(1, 1, 0))};
    const ContactManifold manifold =
        CollideShapes(cylinder, world_from_cylinder, HalfSpace{}, Pose::Identity());
    ASSERT_GE(manifold.point_count, 1);
    EXPECT_NEAR(DeepestSeparation(manifold), -0.004, kExact);
  }
}

// A sphere off the rim: the distance to the rim circle, sqrt((rho - r)^2 +
// (z - h)^2) - R; inside near the cap, the cap depth.
TEST(CylinderSphereTest, DistanceToRimAndCapAreClosedForms) {
  const ShapeGeometry cylinder = Cylinder{0.3, 0.5};
  const ShapeGeometry sphere = Sphere{0.1};
  const Pose world_from_cylinder{Vec3(0.5, 0, 0), AxisAngle(0.3, Vec3::UnitY())};
  const Vec3 local_centre(0.3 + 0.06, 0, 0.5 + 0.08);
  const ContactManifold rim =
      CollideShapes(sphere, Pose{world_from_cylinder * local_centre, Quat::Identity()}, cylinder,
                    world_from_cylinder, 0.05);
  ASSERT_EQ(rim.point_count, 1);
  EXPECT_NEAR(rim.points[0].separation, 0.1 - 0.1, kExact);
  const Vec3 expected_normal = world_from_cylinder.rotation * Vec3(0.6, 0, 0.8);
  EXPECT_LE((rim.normal_world - expected_normal).norm(), kExact);
  const Vec3 inside(0.1, 0.05, 0.5 - 0.02);
  const ContactManifold cap = CollideShapes(
      sphere, Pose{world_from_cylinder * inside, Quat::Identity()}, cylinder, world_from_cylinder);
  ASSERT_EQ(cap.point_count, 1);
  EXPECT_NEAR(cap.points[0].separation, -0.02 - 0.1, kExact);
}

// Against a large box the cylinder meets the box's top face exactly as it
// meets a half-space at the same height.
TEST(CylinderBoxTest, OnALargeBoxFaceMatchesTheHalfSpace) {
  const ShapeGeometry cylinder = Cylinder{0.1, 0.25};
  const ShapeGeometry box =
      std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3(4, 4, 1)));
  for (double tilt : {0.0, 0.3, kPi / 2, 1.2}) {
    SCOPED_TRACE(tilt);
    const double height = 0.25 * std::abs(std::cos(tilt)) + 0.1 * std::sin(tilt) - 0.003;
    const Pose world_from_cylinder{Vec3(0.2, -0.1, height), AxisAngle(tilt, Vec3::UnitX())};
    const ContactManifold on_box =
        CollideShapes(cylinder, world_from_cylinder, box, Pose{Vec3(0, 0, -0.5), Quat::Identity()});
    const ContactManifold on_plane =
        CollideShapes(cylinder, world_from_cylinder, HalfSpace{}, Pose::Identity());
    ASSERT_EQ(on_box.point_count, on_plane.point_count);
    EXPECT_LE((on_box.normal_world - Vec3::UnitZ()).norm(), kExact);
    EXPECT_NEAR(DeepestSeparation(on_box), -0.003, kExact);
    EXPECT_NEAR(DeepestSeparation(on_plane), -0.003, kExact);
  }
}

// Separated cylinder and box in random poses: the separation the narrow
// phase finds is GJK's distance between the box and the cylinder, which a
// 720-sided inscribed prism overestimates by at most
// r (1 - cos(pi / 720)) = 9.5e-6 r.
TEST(CylinderBoxTest, SeparationMatchesGjkOnAFinePrism) {
  const double radius = 0.2;
  const double half_length = 0.3;
  const ShapeGeometry cylinder = Cylinder{radius, half_length};
  const ConvexPolyhedron box_shape = MakeBoxPolyhedron(Vec3(0.4, 0.3, 0.5));
  const ShapeGeometry box = std::make_shared<const ConvexPolyhedron>(box_shape);
  const ConvexPolyhedron prism = MakeCylinderPolyhedron(radius, 2 * half_length, 720);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int compared = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Pose world_from_cylinder{
        Vec3::Zero(), Quat(unit(random), unit(random), unit(random), unit(random)).normalized()};
    const Vec3 direction = Vec3(unit(random), unit(random), unit(random)).normalized();
    const Pose world_from_box{
        direction * (0.45 + 0.1 * (unit(random) + 1.0)),
        Quat(unit(random), unit(random), unit(random), unit(random)).normalized()};
    const GjkResult reference =
        GjkDistance({&prism.vertices, world_from_cylinder, &box_shape.vertices, world_from_box});
    if (reference.overlapping || reference.distance > 0.09) continue;
    const ContactManifold manifold =
        CollideShapes(cylinder, world_from_cylinder, box, world_from_box, 0.1);
    ASSERT_GE(manifold.point_count, 1) << "trial " << trial;
    const double prism_excess = radius * (1.0 - std::cos(kPi / 720));
    EXPECT_GE(DeepestSeparation(manifold), reference.distance - prism_excess - 1e-9)
        << "trial " << trial;
    EXPECT_LE(DeepestSeparation(manifold), reference.distance + 1e-9) << "trial " << trial;
    ++compared;
  }
  EXPECT_GE(compared, 50);
}

BodyId AddCylinder(World* world, const Pose& world_from_body, const Material& material,
                   double radius, double half_length, double mass) {
  BodyDef def;
  def.world_from_body = world_from_body;
  const double volume = kPi * radius * radius * 2 * half_length;
  def.mass_properties = CylinderMassProperties(mass / volume, radius, 2 * half_length);
  ShapeDef shape;
  shape.geometry = Cylinder{radius, half_length};
  shape.material = material;
  def.shapes.push_back(shape);
  return world->CreateBody(def).value();
}

// A static 1 m thick ramp tilted by theta about y, centred at `centre`: its
// top face has normal (sin, 0, cos) and falls along (cos, 0, -sin).
struct Ramp {
  Vec3 top_centre;  // m, the middle of its top face
  Vec3 normal;
  Vec3 downhill;
  Quat tilt;
};

Ramp AddRamp(World* world, double theta, double length, const Vec3& centre, double friction) {
  const Quat tilt = AxisAngle(theta, Vec3::UnitY());
  BoxSpec ramp;
  ramp.size = Vec3(length, 4.0, 1.0);
  ramp.is_static = true;
  ramp.world_from_body = Pose{centre, tilt};
  ramp.material = MakeMaterial(friction, 0.0);
  AddBox(world, ramp);
  const Vec3 normal = tilt * Vec3::UnitZ();
  return Ramp{centre + 0.5 * normal, normal, tilt * Vec3::UnitX(), tilt};
}

// A solid cylinder rolling without slipping down a slope: its centre
// accelerates at a = g sin(theta) / (1 + I / (m r^2)) = (2/3) g sin(theta),
// so it travels a t^2 / 2 from rest. Rolling needs mu >= tan(theta) / 3.
TEST(CylinderRollingTest, RollsDownATenDegreeRampAtTwoThirdsGSinTheta) {
  const double theta = 10 * kDegree;
  World world;
  const Ramp ramp = AddRamp(&world, theta, 40.0, Vec3(0, 0, 5.0), 0.5);
  const Vec3& normal = ramp.normal;
  const Vec3& downhill = ramp.downhill;
  const double radius = 0.1;
  const Pose start{ramp.top_centre + normal * radius - 10.0 * downhill,
                   ramp.tilt * AxisAngle(kPi / 2, Vec3::UnitX())};
  const BodyId cylinder = AddCylinder(&world, start, MakeMaterial(0.5, 0.0), radius, 0.15, 2.0);
  const double t = 2.0;
  const int steps = static_cast<int>(std::lround(t / world.settings().time_step));
  for (int step = 0; step < steps; ++step) world.Step();
  const Vec3 moved = world.GetPose(cylinder).translation - start.translation;
  const double expected = 0.5 * (2.0 / 3.0) * kG * std::sin(theta) * t * t;
  EXPECT_NEAR(moved.dot(downhill) / expected, 1.0, 1e-4);
  EXPECT_NEAR(moved.dot(normal), 0.0, 1e-6);
  // Rolling: the spin is v / r about the axis.
  const double spin = world.GetAngularVelocity(cylinder).norm();
  const double speed = world.GetLinearVelocity(cylinder).norm();
  EXPECT_NEAR(spin * radius / speed, 1.0, 1e-4);
}

// Rolling on flat ground, an exact cylinder keeps its kinetic energy (a
// prism would bump and lose some at every edge).
TEST(CylinderRollingTest, RollsOnFlatGroundWithoutLosingSpeed) {
  World world;
  AddGround(&world, MakeMaterial(0.6, 0.0));
  const double radius = 0.1;
  const BodyId cylinder =
      AddCylinder(&world, Pose{Vec3(0, 0, radius), AxisAngle(kPi / 2, Vec3::UnitX())},
                  MakeMaterial(0.6, 0.0), radius, 0.1, 1.0);
  const double speed = 1.0;
  ASSERT_TRUE(world
                  .SetState(cylinder, world.GetPose(cylinder), Vec3(speed, 0, 0),
                            Vec3(0, speed / radius, 0))
                  .ok());
  for (int step = 0; step < 480; ++step) world.Step();
  EXPECT_NEAR(world.GetLinearVelocity(cylinder).x(), speed, 1e-6 * speed);
  EXPECT_NEAR(world.GetPose(cylinder).translation.x(), 2.0 * speed, 1e-6);
  EXPECT_NEAR(world.GetPose(cylinder).translation.z(), radius, 1e-6);
}

// Standing on its cap on a 20 degree slope with mu = 0.8 > tan(20 deg) =
// 0.36, and r / h = 1 > tan(20 deg) so it does not tip: it stays put.
TEST(CylinderStandingTest, StandsOnItsCapOnATwentyDegreeSlope) {
  const double theta = 20 * kDegree;
  World world;
  const Ramp ramp = AddRamp(&world, theta, 10.0, Vec3(0, 0, 2.0), 0.8);
  const Pose start{ramp.top_centre + ramp.normal * 0.1, ramp.tilt};
  const BodyId cylinder = AddCylinder(&world, start, MakeMaterial(0.8, 0.0), 0.1, 0.1, 1.0);
  double drift = 0.0;
  for (int step = 0; step < 240 * 5; ++step) {
    world.Step();
    drift = std::max(drift, (world.GetPose(cylinder).translation - start.translation).norm());
  }
  EXPECT_LT(drift, 1e-4);
}

// Three cylinders stacked on their caps, the upper two exact against the
// lower's 64-sided prism, and a box on top: nothing moves, and the ground
// carries the whole weight.
TEST(CylinderStandingTest, StackOfCylindersAndABoxRests) {
  World world;
  const BodyId ground = AddGround(&world, MakeMaterial(0.6, 0.0));
  std::vector<BodyId> stack;
  std::vector<Pose> starts;
  double total_mass = 0.0;
  for (int level = 0; level < 3; ++level) {
    starts.push_back(Pose{Vec3(0, 0, 0.15 + 0.3 * level), Quat::Identity()});
    stack.push_back(AddCylinder(&world, starts.back(), MakeMaterial(0.6, 0.0), 0.2, 0.15, 2.0));
    total_mass += 2.0;
  }
  BoxSpec box;
  box.size = Vec3(0.2, 0.2, 0.2);
  box.mass = 1.0;
  box.world_from_body = Pose{Vec3(0, 0, 1.0), Quat::Identity()};
  box.material = MakeMaterial(0.6, 0.0);
  starts.push_back(box.world_from_body);
  stack.push_back(AddBox(&world, box));
  total_mass += 1.0;
  for (int step = 0; step < 240 * 3; ++step) world.Step();
  for (std::size_t i = 0; i < stack.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_LT((world.GetPose(stack[i]).translation - starts[i].translation).norm(), 1e-4);
  }
  double carried = 0.0;
  for (const ContactReport& contact : world.contacts()) {
    if (contact.body_a == ground || contact.body_b == ground) {
      carried += contact.normal_force * std::abs(contact.normal_world.z());
    }
  }
  EXPECT_NEAR(carried / (total_mass * kG), 1.0, 0.01);
}

// A puck (r = 0.1 m, h = 0.03 m) dropped from 0.3 m tilted 0.3 rad lands
// on its rim and falls flat on its cap (z = h); a rod (r = 0.05 m, h = 0.1 m)
// dropped lying, its axis 0.05 rad from horizontal, settles on its side
// (z = r). Both are at rest within 3 s.
TEST(CylinderStandingTest, DroppedCylinderSettlesOnItsCapOrItsSide) {
  for (const bool upright : {true, false}) {
    SCOPED_TRACE(upright);
    const double radius = upright ? 0.1 : 0.05;
    const double half_length = upright ? 0.03 : 0.1;
    World world;
    AddGround(&world, MakeMaterial(0.5, 0.0));
    const Quat tilt =
        upright ? AxisAngle(0.3, Vec3::UnitX()) : AxisAngle(kPi / 2 - 0.05, Vec3(1, 1, 0));
    const BodyId cylinder = AddCylinder(&world, Pose{Vec3(0, 0, 1.0), tilt}, MakeMaterial(0.5, 0.2),
                                        radius, half_length, 0.5);
    for (int step = 0; step < 240 * 3; ++step) world.Step();
    EXPECT_LT(world.GetLinearVelocity(cylinder).norm(), 1e-3);
    EXPECT_LT(world.GetAngularVelocity(cylinder).norm(), 1e-2);
    const double z = world.GetPose(cylinder).translation.z();
    const double axis_z = (world.GetPose(cylinder).rotation * Vec3::UnitZ()).z();
    EXPECT_NEAR(z, upright ? half_length : radius, 1e-3);
    EXPECT_NEAR(std::abs(axis_z), upright ? 1.0 : 0.0, 1e-3);
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics
