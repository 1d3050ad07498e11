// Drops a few bodies from different heights and prints their heights, so a
// fresh build shows the core running without ROS.
#include <cstdio>
#include <vector>

#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/world.h"

int main() {
  namespace physics = rigid_body_sim::physics;
  physics::World world;
  std::vector<physics::BodyId> bodies;
  for (int i = 0; i < 3; ++i) {
    physics::BodyDef def;
    def.mass_properties = physics::BoxMassProperties(1000.0, physics::Vec3(0.5, 0.5, 0.5));
    def.world_from_body.translation = physics::Vec3(i, 0.0, 2.0 + i);
    def.angular_velocity = physics::Vec3(0.0, 1.0 + i, 0.0);
    const physics::Result<physics::BodyId> id = world.CreateBody(def);
    if (!id.ok()) {
      std::fprintf(stderr, "could not create body: %s\n", id.message().c_str());
      return 1;
    }
    bodies.push_back(id.value());
  }
  std::printf("%6s %10s %10s %10s\n", "t [s]", "z0 [m]", "z1 [m]", "z2 [m]");
  for (int step = 0; step <= 120; ++step) {
    if (step % 24 == 0) {
      std::printf("%6.2f", world.time());
      for (const physics::BodyId id : bodies)
        std::printf(" %10.4f", world.GetPose(id).translation.z());
      std::printf("\n");
    }
    world.Step();
  }
  return 0;
}
