// libFuzzer harness for the node's request validation: the bytes are read
// as doubles (any bit pattern: NaN, infinities, 1e300) for a set_state and
// an apply_wrench on a box resting on the ground. Whatever the validation
// accepts, the world must take and step with every body staying finite;
// whatever it refuses must name a field.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "rigid_body_sim/node/request_validation.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/world.h"

namespace {

using rigid_body_sim::physics::Vec3;

struct Reader {
  const std::uint8_t* data;
  std::size_t size;
  double Next() {
    double value = 0.0;
    if (size >= sizeof(value)) {
      std::memcpy(&value, data, sizeof(value));
      data += sizeof(value);
      size -= sizeof(value);
    }
    return value;
  }
  std::uint64_t NextCount() {
    double bits = Next();
    std::uint64_t count = 0;
    std::memcpy(&count, &bits, sizeof(count));
    return count;
  }
  Vec3 NextVec() {
    const double x = Next();
    const double y = Next();
    return Vec3(x, y, Next());
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace node = rigid_body_sim::node;
  namespace physics = rigid_body_sim::physics;
  Reader in{data, size};
  const node::RequestLimits limits;
  physics::World world;
  physics::BodyDef ground;
  ground.is_static = true;
  physics::ShapeDef plane;
  plane.geometry = physics::HalfSpace{};
  ground.shapes.push_back(plane);
  world.CreateBody(ground).value();
  physics::BodyDef box;
  box.mass_properties = physics::BoxMassProperties(1000.0, Vec3(1, 1, 1));
  physics::ShapeDef shape;
  shape.geometry =
      std::make_shared<const physics::ConvexPolyhedron>(physics::MakeBoxPolyhedron(Vec3(1, 1, 1)));
  box.shapes.push_back(shape);
  box.world_from_body.translation = Vec3(0, 0, 0.5);
  const physics::BodyId a = world.CreateBody(box).value();
  box.world_from_body.translation = Vec3(0, 0, 1.5);
  const physics::BodyId b = world.CreateBody(box).value();

  node::FrameState state;
  state.world_from_frame.translation = in.NextVec();
  state.linear_velocity = in.NextVec();
  state.angular_velocity = in.NextVec();
  const physics::Status state_ok = node::ValidateFrameState(state, limits);
  if (!state_ok.ok() && state_ok.message().find("twist") == std::string::npos &&
      state_ok.message().find("pose") == std::string::npos) {
    std::abort();
  }
  if (state_ok.ok() &&
      !world.SetState(a, state.world_from_frame, state.linear_velocity, state.angular_velocity)
           .ok()) {
    std::abort();
  }
  const Vec3 force = in.NextVec();
  const Vec3 torque = in.NextVec();
  const Vec3 point = in.NextVec();
  const double duration = in.Next();
  const double time_step = in.Next();
  if (node::ValidateWrench(force, torque, point, duration, limits).ok()) {
    if (!world.ApplyForceAtPoint(b, force, point).ok() || !world.ApplyTorque(b, torque).ok()) {
      std::abort();
    }
    if (node::ValidateTimeStep(time_step, "time_step").ok()) {
      if (node::WrenchSteps(duration, time_step) < 1) std::abort();
      physics::WorldSettings settings = world.settings();
      settings.time_step = time_step;
      if (!world.SetSettings(settings).ok()) std::abort();
    }
  }
  (void)node::ValidateStepCount(in.NextCount(), limits);
  (void)node::ValidateRealTimeFactor(in.Next(), "real_time_factor");
  for (int i = 0; i < 3; ++i) {
    world.Step();
    // Accepted input never comes near the step guard's bounds.
    if (!world.non_finite_bodies().empty()) std::abort();
  }
  if (!world.GetBody(a).HasFiniteState() || !world.GetBody(b).HasFiniteState()) std::abort();
  return 0;
}
