// Rigid bodies: the definition callers fill in, and the state the world keeps.
#ifndef RIGID_BODY_SIM_PHYSICS_BODY_H_
#define RIGID_BODY_SIM_PHYSICS_BODY_H_

#include <array>
#include <cstdint>
#include <vector>

#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/shape.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// Everything needed to create a body. The body frame is the caller's frame
// (for URDF bodies, the root link frame); the centre-of-mass offset and the
// principal axes are kept internally, so poses come back in this frame.
struct BodyDef {
  Pose world_from_body;                  // m, unit quaternion
  Vec3 linear_velocity = Vec3::Zero();   // m/s, world frame, of the body frame origin
  Vec3 angular_velocity = Vec3::Zero();  // rad/s, world frame
  bool is_static = false;                // infinite mass; never moves
  MassProperties mass_properties;        // kg, m, kg m^2 in the body frame; unused when static
  std::vector<ShapeDef> shapes;          // in the body frame
  std::uint64_t user_data = 0;           // opaque to the core
};

// State of one body, after Baraff's state vector Y = (x, q, P, L); the rest
// is derived from it and cached. Internally the body is kept in its
// principal frame: q is world_from_principal, so the body-frame inertia is
// diagonal and I_world^-1 = R diag(1/I) R^T.
struct Body {
  Vec3 position = Vec3::Zero();          // x: centre of mass, world, m
  Quat orientation = Quat::Identity();   // q: world_from_principal
  Vec3 linear_momentum = Vec3::Zero();   // P, kg m/s
  Vec3 angular_momentum = Vec3::Zero();  // L about the centre of mass, world, kg m^2/s

  Vec3 linear_velocity = Vec3::Zero();        // v = P / M, m/s
  Vec3 angular_velocity = Vec3::Zero();       // omega = I_world^-1 L, rad/s
  Mat3 inverse_inertia_world = Mat3::Zero();  // 1/(kg m^2)

  double mass = 0.0;          // kg; 0 for static bodies
  double inverse_mass = 0.0;  // 1/kg; 0 for static bodies
  Vec3 inverse_principal_moments = Vec3::Zero();
  Pose principal_from_body;  // the body frame seen from the principal frame

  Vec3 force = Vec3::Zero();                    // N, world, accumulated for the next step
  Vec3 torque = Vec3::Zero();                   // N m, world, about the centre of mass
  Vec3 start_linear_velocity = Vec3::Zero();    // m/s, v before this step's forces
  Vec3 start_angular_momentum = Vec3::Zero();   // kg m^2/s, L before this step's torques
  Vec3 pseudo_linear_velocity = Vec3::Zero();   // m/s, split-impulse correction of this step
  Vec3 pseudo_angular_velocity = Vec3::Zero();  // rad/s

  std::vector<ShapeDef> shapes;  // in the body frame
  double thickness = 0.0;        // m, smallest width of any shape; bounds motion per sample
  double bounding_radius = 0.0;  // m, largest distance of any shape point from the centre of mass
  // m; the steps' bounds on how far any point of the body moved, summed
  // since it was created. A pair found apart by a gap g stays apart while
  // the travel of its two bodies since then is below g minus the contact
  // distance, with no need to look at it (World::CollideBodies).
  double travel = 0.0;
  // Per shape, the vertices its polyhedron reached furthest along +x, -x,
  // +y, -y, +z, -z of the world when the broad phase last boxed it: the
  // next step's support climbs start there, a step or two from the answer.
  std::vector<std::array<int, 6>> box_support;

  bool is_static = false;
  bool awake = true;
  double sleep_time = 0.0;  // s the body has been slow enough to sleep
  // s its speed (or its angular speed) has grown at every step, above the
  // noise; with the speeds at the end of the previous step.
  double speeding_up_time = 0.0;
  double last_speed = 0.0;          // m/s
  double last_angular_speed = 0.0;  // rad/s
  bool has_proxy = false;           // registered with the broad phase
  bool disabled = false;            // its state became non-finite; out of the simulation
  // The articulation the body is a link of, and which link; -1 for a free
  // body. A link moves with its articulation's joint coordinates, never on
  // its own.
  std::int32_t articulation = -1;
  std::int32_t link = -1;
  std::uint64_t user_data = 0;
  std::uint32_t generation = 0;
  bool in_use = false;

  Pose WorldFromPrincipal() const { return Pose{position, orientation}; }
  Pose WorldFromBody() const { return WorldFromPrincipal() * principal_from_body; }
  // Velocity of the material point currently at `point_world`.
  Vec3 PointVelocity(const Vec3& point_world) const {
    return linear_velocity + angular_velocity.cross(point_world - position);
  }
  // Recomputes v, omega and I_world^-1 from the state (x, q, P, L).
  void UpdateDerived();
  bool HasFiniteState() const {
    return position.allFinite() && orientation.coeffs().allFinite() &&
           linear_momentum.allFinite() && angular_momentum.allFinite();
  }
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_BODY_H_
