// Benchmark scenes, described once and built by every engine under test.
#ifndef RIGID_BODY_SIM_BENCH_SCENE_H_
#define RIGID_BODY_SIM_BENCH_SCENE_H_

#include <string>
#include <vector>

#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::bench {

using physics::kPi;
using physics::Pose;
using physics::Quat;
using physics::Vec3;

// s, the step of every scene unless it sets another (Scene::time_step).
constexpr double kDefaultTimeStep = 1.0 / 240.0;
// m/s^2, along -z in every engine.
constexpr double kGravity = 9.81;

// Material as our engine combines it: e = max(e_a, e_b),
// mu = sqrt(mu_a mu_b). Engines with other rules convert (bullet_engine.cc).
struct BenchMaterial {
  double friction = 0.5;     // Coulomb coefficient, dimensionless
  double restitution = 0.0;  // coefficient of restitution, [0, 1]
};

struct BenchBody {
  enum class Shape { kBox, kSphere };
  Shape shape = Shape::kBox;
  Vec3 box_size = Vec3::Ones();  // m, full edge lengths (boxes)
  double sphere_radius = 0.0;    // m (spheres)
  double mass = 1.0;             // kg, uniform density
  Pose world_from_body;          // m; the body frame is the shape's centre
  BenchMaterial material;
};

// What the scene measures besides the time per step.
enum class SceneKind {
  kPile,     // drift of the top box: horizontal distance from its start column
  kPyramid,  // drift of the top box: distance from its start (it should not move)
  kBounce,   // first apex of the sphere against e^2 h
  kIncline,  // distance slid along the slope against 1/2 g (sin - mu cos) t^2
  kChain,    // largest joint anchor separation over the run (it should be ~0)
  kArmPush,  // boxes the arm pushed, and how far its driven joint turned
  kTerrain,  // time until every body is at rest, and bodies whose centre ended below the surface
  kLimpArm,  // energy drift of an arm swinging under gravity with no motors
  kHeldArm,  // servo error of an arm whose velocity motors hold it still
};

// The hills of the terrain scenes: z = amplitude sin(x / wavelength)
// cos(y / wavelength), m.
struct Hills {
  double amplitude = 0.0;
  double wavelength = 1.0;
  double HeightAt(double x, double y) const;
};

// A link of an articulation: a rigid body in its link frame, which the
// joint from its parent moves; inertia diagonal in the link frame.
struct BenchLink {
  double mass = 1.0;                     // kg
  Vec3 center_of_mass = Vec3::Zero();    // m, link frame
  Vec3 inertia_diagonal = Vec3::Ones();  // kg m^2, about the centre of mass
  // A box collision shape centred on the centre of mass, its axes along the
  // link frame's.
  bool has_box = false;
  Vec3 box_size = Vec3::Ones();  // m, full edge lengths
  BenchMaterial material;
};

// A revolute joint: the child link frame is the parent link frame moved by
// `parent_offset` and turned by the joint angle about `axis` (both in the
// parent frame; the frames agree at angle 0).
struct BenchJoint {
  int parent = 0;                     // index into BenchArticulation::links, below the child's
  Vec3 parent_offset = Vec3::Zero();  // m
  Vec3 axis = Vec3::UnitY();          // unit
  double position = 0.0;              // rad, initial
  double effort_limit = 1e9;          // N m, the motor's
};

// One piecewise-constant velocity command for a joint's motor.
struct MotorPhase {
  double from_seconds = 0.0;  // s of simulated time
  double velocity = 0.0;      // rad/s
};

// A fixed-base tree of revolute joints; joint j moves links[j + 1]. The
// base has no collision shape.
struct BenchArticulation {
  Pose world_from_base;
  std::vector<BenchLink> links;  // links[0] is the base, fixed to the world
  std::vector<BenchJoint> joints;
  // Velocity motors, per joint: none (limp) or phases in time order.
  std::vector<std::vector<MotorPhase>> motors;
};

struct Scene {
  std::string name;
  SceneKind kind = SceneKind::kPile;
  // The ground: the half-space below the plane through the origin of
  // world_from_ground with normal +z of that frame.
  Pose world_from_ground;
  BenchMaterial ground_material;
  std::vector<BenchBody> bodies;
  double seconds = 10.0;                // s of simulated time
  double time_step = kDefaultTimeStep;  // s, every engine's step
  int top_body = -1;                    // index of the body whose drift is reported
  double drop_height = 0.0;             // m, bounce: fall of the sphere's lowest point
  double slope_degrees = 0.0;           // incline: slope angle
  // Articulated scenes: one articulation beside the free bodies.
  std::vector<BenchArticulation> articulations;
  int driven_joint = -1;  // arm: the joint whose swept angle is reported
  // When it has triangles, the ground is this static mesh (world frame)
  // instead of the half-space, sampling `hills`.
  physics::TriangleMesh terrain;
  Hills hills;
};

// pile_N: unit boxes (1 m, 1 kg, mu 0.5, e 0) in a square grid of
// ceil(cbrt(N)) x ceil(cbrt(N)) columns 1.1 m apart, layers 1.2 m apart from
// z = 0.6, each layer yawed a further 0.1 rad, back to 0 after 0.4 rad
// (scene.cc: beyond 0.43 rad neighbours would start inside each other).
Scene MakePile(int count, double seconds);
// pyramid_R: R rows of unit boxes (mu 0.6) touching side by side, row r
// holding R - r boxes; R (R + 1) / 2 boxes in all.
Scene MakePyramid(int rows, double seconds);
// bounce: a sphere of r 0.1 m, 1 kg, e 0.5, its lowest point 1 m above the
// ground, released at rest.
Scene MakeBounce();
// incline: a unit box (1 kg, mu 0.5) at rest on a slope of `degrees`, for 2 s.
Scene MakeIncline(double degrees);
// chain_30: 30 links of 0.1 m and 0.1 kg (point masses at their ends) and a
// 100 kg tip, hinged about y, released horizontal from a fixed base 3.5 m up,
// swinging for 10 s, with no collision shapes.
Scene MakeChain(int links, double seconds);
// arm_push_100: a fixed-base arm (yaw, shoulder and elbow, box links) whose
// yaw motor sweeps it through 100 boxes of 0.1 m on the ground and back
// (scene.cc); shoulder and elbow motors hold them still.
Scene MakeArmPush(int boxes, double seconds);

// J: sum over the bodies that can move of m g |c - o|, c a body's centre
// of mass at the start and o the base of the first articulation (the
// world's origin without one): the most potential energy a body that stays
// that far from o can trade, and the scale an articulated run's energy
// drift is measured against (measure.h).
double EnergyScale(const Scene& scene);

// The scene stepped at `hz` steps per second instead of 240: its name
// gains "_<hz>hz" (none at 240 Hz, so the rows of earlier runs keep theirs).
Scene AtStepRate(Scene scene, int hz);

// panda_like (limp) and panda_held: a fixed-base 7-DOF arm with the masses,
// centres of mass and the diagonals of the inertias of Franka Emika's
// published Panda model (arm_scenes.cc; no hand), started in the Panda's
// "ready" pose. Limp: no motors, no damping, it swings under gravity; the
// energy should stay constant. Held: each joint's velocity motor commands 0
// with the Panda's torque limits (87 N m on joints 1-4, 12 N m on 5-7).
Scene MakePandaLike(bool held, double seconds);
// ur5_like: a fixed-base 6-DOF arm with Universal Robots' published UR5
// link lengths (DH), masses and centres of mass, limp, released stretched
// out horizontally.
Scene MakeUr5Like(double seconds);

// terrain_N: N unit boxes (1 kg, mu 0.5) dropped from 1 m above rolling
// hills (amplitude 0.5 m unless given, wavelength 3 m) made of `triangles` (rounded up
// to a square grid) over 40 x 40 m, in a square grid 3 m apart, each yawed
// 0.3 rad more than the last. terrain_flat_N: the same drop onto the flat
// half-space, the reference for the terrain's cost.
Scene MakeTerrain(int count, int triangles, double seconds, double amplitude = 0.5);
Scene MakeFlatTerrain(int count, double seconds);

}  // namespace rigid_body_sim::bench

#endif  // RIGID_BODY_SIM_BENCH_SCENE_H_
