// Bit-exact reproducibility of a simulation: the node's ~reset and anyone
// replaying a recorded scene rely on the same input giving the same motion,
// not a close one, so the whole state is hashed bit for bit.
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/types.h"
#include "rigid_body_sim/physics/world.h"
#include "scene.h"
#include "state_hash.h"

namespace rigid_body_sim::physics {
namespace {

using testing::AddBox;
using testing::AddGround;
using testing::AddSphere;
using testing::BoxSpec;
using testing::MakeMaterial;
using testing::SphereSpec;
using testing::StateHash;
using testing::Translation;

constexpr int kSteps = 1000;
constexpr int kMidSteps = 500;

// A body as it was spawned, so that it can be put back there.
struct Spawn {
  BodyId id;
  Pose pose;
  Vec3 linear_velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();
};

std::uint64_t HashState(const World& world, const std::vector<Spawn>& bodies) {
  StateHash hash;
  for (const Spawn& body : bodies) {
    const Pose pose = world.GetPose(body.id);
    hash.Add(pose.translation);
    const Eigen::Vector4d coeffs = pose.rotation.coeffs();
    for (int i = 0; i < 4; ++i) hash.Add(coeffs[i]);
    hash.Add(world.GetLinearVelocity(body.id));
    hash.Add(world.GetAngularVelocity(body.id));
  }
  hash.Add(world.time());
  return hash.value();
}

// 30 bodies, 20 boxes of three sizes and 10 spheres, in four layers of a
// 3 x 3 grid of columns, each a few centimetres off the grid, tilted, and
// thrown inwards and spinning, so that they hit each other in the air, land
// on each other and on the ground, and settle into a pile. The spheres
// bounce (restitution 0.3) and the boxes do not, so both the collision
// rounds and the resting solve run. The grid is 0.85 m wide and the largest
// body fits in a ball of 0.38 m, so nothing overlaps as spawned. The ground
// comes first in the returned list.
std::vector<Spawn> BuildPile(World* world) {
  std::vector<Spawn> bodies;
  Spawn ground;
  ground.id = AddGround(world, MakeMaterial(0.6, 0.0));
  bodies.push_back(ground);
  for (int n = 0; n < 30; ++n) {
    const int layer = n / 9;
    const int cell = n % 9;
    const double x = 0.85 * (cell % 3 - 1) + 0.03 * std::sin(1.7 * n);
    const double y = 0.85 * (cell / 3 - 1) + 0.03 * std::cos(2.3 * n);
    const double z = 0.45 + 0.85 * layer;
    Spawn spawn;
    spawn.pose = Translation(x, y, z);
    spawn.linear_velocity = Vec3(-0.4 * x, -0.4 * y, -0.2 * (n % 4));
    if (n % 3 == 2) {
      SphereSpec spec;
      spec.radius = 0.15 + 0.02 * (n % 2);
      spec.mass = 0.5;
      spec.world_from_body = spawn.pose;
      spec.linear_velocity = spawn.linear_velocity;
      spec.material = MakeMaterial(0.5, 0.3);
      spawn.id = AddSphere(world, spec);
    } else {
      spawn.pose.rotation = Quat(
          Eigen::AngleAxisd(0.3 * std::sin(n), Vec3(1.0, 0.5 * std::cos(n), 0.3).normalized()));
      spawn.angular_velocity = Vec3(0.5 * std::sin(n), 0.5 * std::cos(n), 0.2);
      BoxSpec spec;
      spec.size = Vec3(0.4 + 0.05 * (n % 2), 0.4, 0.35 + 0.05 * (n % 3));
      spec.mass = 1.0 + 0.5 * (n % 3);
      spec.world_from_body = spawn.pose;
      spec.linear_velocity = spawn.linear_velocity;
      spec.angular_velocity = spawn.angular_velocity;
      spec.material = MakeMaterial(0.5, 0.0);
      spawn.id = AddBox(world, spec);
    }
    bodies.push_back(spawn);
  }
  return bodies;
}

// What a run of kSteps steps did, to compare runs by and to show the run
// was not trivial.
struct Trajectory {
  std::uint64_t mid_hash = 0;          // after kMidSteps steps
  std::uint64_t final_hash = 0;        // after kSteps steps
  double largest_displacement = 0.0;   // m, of any body from its spawn position, at the end
  std::size_t most_solver_points = 0;  // contact points of the busiest step
  std::size_t fewest_awake = 0;        // awake bodies at the quietest step
};

Trajectory Simulate(World* world, const std::vector<Spawn>& bodies) {
  Trajectory trajectory;
  trajectory.fewest_awake = world->AwakeBodyCount();
  for (int step = 1; step <= kSteps; ++step) {
    world->Step();
    trajectory.most_solver_points =
        std::max(trajectory.most_solver_points, world->last_step_profile().solver_points);
    trajectory.fewest_awake = std::min(trajectory.fewest_awake, world->AwakeBodyCount());
    if (step == kMidSteps) trajectory.mid_hash = HashState(*world, bodies);
  }
  trajectory.final_hash = HashState(*world, bodies);
  for (const Spawn& body : bodies) {
    trajectory.largest_displacement =
        std::max(trajectory.largest_displacement,
                 (world->GetPose(body.id).translation - body.pose.translation).norm());
  }
  return trajectory;
}

void Print(const char* what, const Trajectory& trajectory) {
  std::printf(
      "%s: step %d %016" PRIx64 ", step %d %016" PRIx64
      "; largest displacement %.3f m, at most %zu contact points, at least %zu bodies awake\n",
      what, kMidSteps, trajectory.mid_hash, kSteps, trajectory.final_hash,
      trajectory.largest_displacement, trajectory.most_solver_points, trajectory.fewest_awake);
}

TEST(DeterminismTest, TwoWorldsBuiltAlikeMoveAlikeBitForBit) {
  World first;
  World second;
  const std::vector<Spawn> first_bodies = BuildPile(&first);
  const std::vector<Spawn> second_bodies = BuildPile(&second);
  const std::uint64_t initial_hash = HashState(first, first_bodies);
  ASSERT_EQ(HashState(second, second_bodies), initial_hash);
  std::printf("initial: %016" PRIx64 "\n", initial_hash);

  const Trajectory first_run = Simulate(&first, first_bodies);
  const Trajectory second_run = Simulate(&second, second_bodies);
  Print("first world", first_run);
  Print("second world", second_run);

  // The run is not trivial, so equal hashes below mean something: the state
  // changed between the three hashes, bodies fell and slid, many contact
  // points were solved in one step, and at some point part of the pile
  // slept (all but the ground are dynamic).
  EXPECT_NE(first_run.mid_hash, initial_hash);
  EXPECT_NE(first_run.mid_hash, first_run.final_hash);
  EXPECT_GT(first_run.largest_displacement, 0.1);
  EXPECT_GT(first_run.most_solver_points, 40u);
  EXPECT_LT(first_run.fewest_awake, first_bodies.size() - 1);

  EXPECT_EQ(second_run.mid_hash, first_run.mid_hash);
  EXPECT_EQ(second_run.final_hash, first_run.final_hash);
}

// World::Restart forgets contact caches, warm starts and sleep timers, so a
// world put back to its spawn state and restarted must run as a new one
// does, even though the bodies' slots, the broad phase's sorted lists and the
// contact cache's storage have been through a run already.
TEST(DeterminismTest, WorldPutBackToItsSpawnStateAndRestartedMovesAsANewOneBitForBit) {
  World reference;
  const std::vector<Spawn> reference_bodies = BuildPile(&reference);
  const std::uint64_t initial_hash = HashState(reference, reference_bodies);
  const Trajectory reference_run = Simulate(&reference, reference_bodies);
  Print("new world", reference_run);

  World world;
  const std::vector<Spawn> bodies = BuildPile(&world);
  Simulate(&world, bodies);
  for (const Spawn& body : bodies) {
    ASSERT_TRUE(
        world.SetState(body.id, body.pose, body.linear_velocity, body.angular_velocity).ok());
  }
  world.Restart();
  // The spawn state itself comes back exactly (time 0 included) ...
  EXPECT_EQ(HashState(world, bodies), initial_hash);
  const Trajectory rerun = Simulate(&world, bodies);
  Print("restarted world", rerun);
  // ... and so does every state after it.
  EXPECT_EQ(rerun.mid_hash, reference_run.mid_hash);
  EXPECT_EQ(rerun.final_hash, reference_run.final_hash);
  EXPECT_NE(rerun.final_hash, initial_hash);
}

// The same for an articulation: a heavy-tipped chain, whose free steps split
// where its whip needs it, set back to its start state runs as a new one:
// the splits and the joint rows' warm starts of the first run are forgotten.
TEST(DeterminismTest, ArticulationPutBackToItsStartStateMovesAsANewOneBitForBit) {
  ArticulationDef def;
  def.fixed_base = true;
  LinkDef anchor;
  anchor.mass_properties.mass = 1.0;
  anchor.mass_properties.inertia_about_com = Mat3::Identity() * 0.01;
  def.links.push_back(anchor);
  constexpr int kLinks = 12;
  std::vector<double> start;
  for (int i = 1; i <= kLinks; ++i) {
    LinkDef rod;
    rod.mass_properties.mass = i == kLinks ? 100.0 : 0.1;
    rod.mass_properties.center_of_mass = Vec3(0, 0, -0.1);
    rod.mass_properties.inertia_about_com = Mat3::Identity() * rod.mass_properties.mass * 1e-4;
    def.links.push_back(rod);
    JointDef hinge;
    hinge.name = "j" + std::to_string(i);
    hinge.type = JointType::kContinuous;
    hinge.parent_link = i - 1;
    hinge.child_link = i;
    hinge.parent_from_joint.translation = Vec3(0, 0, i == 1 ? 0.0 : -0.1);
    hinge.axis = Vec3::UnitY();
    hinge.position = i == 1 ? 1.2 : 0.0;
    start.push_back(hinge.position);
    def.joints.push_back(hinge);
  }
  auto run = [&](World* world, ArticulationId id) {
    std::vector<double> angles;
    for (int step = 0; step < 480; ++step) {
      world->Step();
      for (const JointState& joint : world->GetJointStates(id)) angles.push_back(joint.position);
    }
    return angles;
  };
  World reference;
  const ArticulationId reference_id = reference.CreateArticulation(def).value();
  const std::vector<double> first = run(&reference, reference_id);

  World world;
  const ArticulationId id = world.CreateArticulation(def).value();
  run(&world, id);
  ASSERT_TRUE(world.SetJointStates(id, start, std::vector<double>(kLinks, 0.0)).ok());
  world.Restart();
  const std::vector<double> rerun = run(&world, id);
  ASSERT_EQ(rerun.size(), first.size());
  for (std::size_t k = 0; k < first.size(); ++k) {
    ASSERT_EQ(rerun[k], first[k]) << "step " << k / kLinks << ", joint " << k % kLinks;
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics
