// chain_scaling_bench: the cost of one step of an articulated chain against
// its number of movable joints, for ~max_joints_per_model (docs/limits.md).
// A chain of rods hinged about y hangs from a fixed base, its last rod
// 1000 times heavier (chain_30's whip), swinging under gravity from 0.3 rad
// per joint at dt = 1/240 s; one thread.
//
// With --uniform, every rod weighs the same (no whip): the plain hanging
// chain. With --damped, every joint has 0.01 N m s/rad of damping, as many
// URDFs give.
//
// Usage: chain_scaling_bench [--uniform] [--damped] [STEPS [JOINTS...]]
//        (default 480; 30 50 64 100)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/world.h"

namespace {

using rigid_body_sim::physics::ArticulationDef;
using rigid_body_sim::physics::JointDef;
using rigid_body_sim::physics::JointType;
using rigid_body_sim::physics::LinkDef;
using rigid_body_sim::physics::Mat3;
using rigid_body_sim::physics::Vec3;
using rigid_body_sim::physics::World;
using rigid_body_sim::physics::WorldSettings;

constexpr double kRodLength = 0.1;  // m

// A rod of `mass` kg along -z of its link frame, its mass at its end.
LinkDef Rod(double mass) {
  LinkDef link;
  link.mass_properties.mass = mass;
  link.mass_properties.center_of_mass = Vec3(0, 0, -kRodLength);
  link.mass_properties.inertia_about_com = Mat3::Identity() * mass * 1e-4;
  return link;
}

ArticulationDef Chain(int joints, double tip_ratio, double damping) {
  ArticulationDef def;
  def.fixed_base = true;
  def.world_from_base.translation = Vec3(0, 0, 100);
  LinkDef base;
  base.mass_properties.mass = 1.0;
  base.mass_properties.inertia_about_com = Mat3::Identity() * 0.01;
  def.links.push_back(base);
  for (int i = 1; i <= joints; ++i) {
    def.links.push_back(Rod(i == joints ? tip_ratio : 1.0));
    JointDef joint;
    joint.name = "j" + std::to_string(i);
    joint.type = JointType::kContinuous;
    joint.parent_link = i - 1;
    joint.child_link = i;
    joint.parent_from_joint.translation = Vec3(0, 0, i == 1 ? 0.0 : -kRodLength);
    joint.axis = Vec3::UnitY();
    joint.position = 0.3;
    joint.damping = damping;
    def.joints.push_back(joint);
  }
  return def;
}

}  // namespace

int main(int argc, char** argv) {
  int first = 1;
  bool uniform = false;
  bool damped = false;
  for (; first < argc && argv[first][0] == '-'; ++first) {
    const std::string flag = argv[first];
    uniform = uniform || flag == "--uniform";
    damped = damped || flag == "--damped";
  }
  const int steps = argc > first ? std::atoi(argv[first]) : 480;
  std::vector<int> sizes;
  for (int i = first + 1; i < argc; ++i) sizes.push_back(std::atoi(argv[i]));
  if (sizes.empty()) sizes = {30, 50, 64, 100};
  std::printf("movable joints, mean ms/step, worst ms/step (%d steps, %s%s, dt 1/240 s)\n", steps,
              uniform ? "uniform rods" : "heavy tip", damped ? ", damped" : "");
  for (const int joints : sizes) {
    WorldSettings settings;
    settings.time_step = 1.0 / 240.0;
    World world(settings);
    if (!world.CreateArticulation(Chain(joints, uniform ? 1.0 : 1000.0, damped ? 0.01 : 0.0))
             .ok()) {
      std::printf("%d: refused\n", joints);
      continue;
    }
    double total = 0.0;
    double worst = 0.0;
    for (int step = 0; step < steps; ++step) {
      const auto start = std::chrono::steady_clock::now();
      world.Step();
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      total += ms;
      worst = std::max(worst, ms);
    }
    std::printf("%d, %.2f, %.2f\n", joints, total / steps, worst);
  }
  return 0;
}
