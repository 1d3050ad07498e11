// The robot-arm scenes: a Panda-like and a UR5-like arm (scene.h).
//
// BenchJoint wants each link frame parallel to its parent's at angle 0, so
// the published models, whose frames turn from link to link
// (Denavit-Hartenberg), are rewritten here in frames parallel to the world
// in the zero configuration, each with its origin on its joint's axis: the
// offsets, axes and centres of mass below are the published ones turned
// into those frames, and each inertia keeps its published diagonal, turned
// likewise (the products of inertia are left out: "-like").
#include <vector>

#include "scene.h"

namespace rigid_body_sim::bench {
namespace {

struct ArmLink {
  double mass;    // kg
  Vec3 center;    // m, in the link frame
  Vec3 inertia;   // kg m^2, diagonal about the centre of mass
  Vec3 offset;    // m, the joint's anchor in the parent frame
  Vec3 axis;      // unit, the joint's axis
  double effort;  // N m, the joint's torque limit
};

BenchArticulation MakeArm(const BenchLink& base, const std::vector<ArmLink>& links,
                          const std::vector<double>& start) {
  BenchArticulation arm;
  arm.world_from_base.translation = Vec3(0.0, 0.0, 1.0);  // the arms swing below their base
  arm.links.push_back(base);
  for (std::size_t i = 0; i < links.size(); ++i) {
    BenchLink link;
    link.mass = links[i].mass;
    link.center_of_mass = links[i].center;
    link.inertia_diagonal = links[i].inertia;
    arm.links.push_back(link);
    BenchJoint joint;
    joint.parent = static_cast<int>(i);
    joint.parent_offset = links[i].offset;
    joint.axis = links[i].axis;
    joint.position = start[i];
    joint.effort_limit = links[i].effort;
    arm.joints.push_back(joint);
  }
  arm.motors.resize(arm.joints.size());
  return arm;
}

}  // namespace

// Franka Emika's published Panda model (franka_description, as MuJoCo
// Menagerie carries it): joints 1-7 at 0.333 m up, then 0.316 m up, 0.0825 m
// out, -0.0825 m out and 0.384 m up, and 0.088 m out; masses 4.97, 0.65,
// 3.23, 3.59, 1.23, 1.67 and 0.74 kg. Zero configuration: straight up,
// joint axes z, y, z, -y, z, -y, -z. Start: the "ready" pose
// (0, -pi/4, 0, -3 pi/4, 0, pi/2, pi/4).
Scene MakePandaLike(bool held, double seconds) {
  Scene scene;
  scene.name = held ? "panda_held" : "panda_like";
  scene.kind = held ? SceneKind::kHeldArm : SceneKind::kLimpArm;
  scene.seconds = seconds;
  const Vec3 x = Vec3::UnitX();
  const Vec3 y = Vec3::UnitY();
  const Vec3 z = Vec3::UnitZ();
  const std::vector<ArmLink> links = {
      {4.970684, Vec3(0.003875, 0.002081, -0.04762), Vec3(0.70337, 0.70661, 0.009117),
       Vec3(0.0, 0.0, 0.333), z, 87.0},
      {0.646926, Vec3(-0.003141, 0.003495, 0.02872), Vec3(0.007962, 0.025995, 0.02811),
       Vec3::Zero(), y, 87.0},
      {3.228604, Vec3(0.027518, 0.039252, -0.066502), Vec3(0.037242, 0.036155, 0.01083),
       Vec3(0.0, 0.0, 0.316), z, 87.0},
      {3.587895, Vec3(-0.05317, -0.027454, 0.104419), Vec3(0.025853, 0.028323, 0.019552),
       0.0825 * x, -y, 87.0},
      {1.225946, Vec3(-0.011953, 0.041065, -0.038437), Vec3(0.035549, 0.029474, 0.008627),
       Vec3(-0.0825, 0.0, 0.384), z, 12.0},
      {1.666555, Vec3(0.060149, 0.010517, -0.014117), Vec3(0.001964, 0.005433, 0.004354),
       Vec3::Zero(), -y, 12.0},
      {0.735522, Vec3(0.010517, 0.004252, -0.061597), Vec3(0.012516, 0.010027, 0.004815), 0.088 * x,
       -z, 12.0}};
  BenchLink base;
  base.mass = 0.629769;
  base.inertia_diagonal = Vec3(0.00315, 0.00388, 0.004285);
  BenchArticulation arm =
      MakeArm(base, links, {0.0, -kPi / 4, 0.0, -3 * kPi / 4, 0.0, kPi / 2, kPi / 4});
  if (held) {
    for (std::vector<MotorPhase>& motor : arm.motors) motor = {MotorPhase{0.0, 0.0}};
  }
  scene.articulations.push_back(arm);
  return scene;
}

// Universal Robots' published UR5 parameters (its "DH parameters for
// calculations of kinematics and dynamics"): d1 0.089159, a2 -0.425,
// a3 -0.39225, d4 0.10915, d5 0.09465, d6 0.0823 m; masses 3.7, 8.393,
// 2.33, 1.219, 1.219 and 0.1879 kg with their centres of mass. UR publishes
// no inertias; these are the solid-cylinder estimates common in open UR5
// models. Zero configuration: stretched out along -x at the shoulder's
// height, joint axes z, -y, -y, -y, -z, -y; it starts there, limp.
Scene MakeUr5Like(double seconds) {
  Scene scene;
  scene.name = "ur5_like";
  scene.kind = SceneKind::kLimpArm;
  scene.seconds = seconds;
  const Vec3 y = Vec3::UnitY();
  const Vec3 z = Vec3::UnitZ();
  const std::vector<ArmLink> links = {
      {3.7, Vec3(0.0, -0.00193, 0.063549), Vec3(0.0084, 0.0084, 0.0064), Vec3::Zero(), z, 150.0},
      {8.393, Vec3(-0.2125, -0.11336, 0.0), Vec3(0.0078, 0.21, 0.21), Vec3(0.0, 0.0, 0.089159), -y,
       150.0},
      {2.33, Vec3(-0.24225, -0.0265, 0.0), Vec3(0.0016, 0.0462, 0.0462), Vec3(-0.425, 0.0, 0.0), -y,
       150.0},
      {1.219, Vec3(0.0, -0.10735, -0.01634), Vec3(0.0016, 0.0016, 0.0009), Vec3(-0.39225, 0.0, 0.0),
       -y, 28.0},
      {1.219, Vec3(0.0, -0.01634, -0.09285), Vec3(0.0016, 0.0009, 0.0016), Vec3(0.0, -0.10915, 0.0),
       -z, 28.0},
      {0.1879, Vec3(0.0, -0.081141, 0.0), Vec3(0.0001, 0.0001, 0.0001), Vec3(0.0, 0.0, -0.09465),
       -y, 28.0}};
  BenchLink base;
  base.mass = 4.0;
  base.inertia_diagonal = Vec3::Constant(0.0072);
  scene.articulations.push_back(MakeArm(base, links, std::vector<double>(links.size(), 0.0)));
  return scene;
}

}  // namespace rigid_body_sim::bench
