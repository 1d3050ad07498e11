// How far a body has moved lately, for the sleep test: a body whose points
// have all stayed within small spheres for time_to_sleep is at rest however
// its velocity swings. Rocking on a gently curved surface (a box on a
// saddle of a terrain) is nearly conservative in exact rigid-body dynamics,
// so its speed stays above a velocity threshold long after the box has
// stopped going anywhere.
//
// Three points of the body, its centre of mass c and c + d R e_x,
// c + d R e_y (R: world_from_principal), are each kept in a sphere grown to
// take in every position the point had since the window started (Ritter,
// "An efficient bounding sphere", Graphics Gems, 1990: a point outside the
// sphere moves its centre towards the point and grows its radius to
// (r + |p - c|) / 2). When a sphere's radius passes the limit, the window
// starts again from the body's current pose. The test follows the one Jolt
// Physics documents (Rouwe, Jolt Physics, "Sleeping": the movement of
// points of the body over mTimeBeforeSleep).
//
// With d = linear_velocity / angular_velocity and the limit
// r = linear_velocity time_to_sleep / 2, steady motion stays in the window
// exactly as long as it stays below the velocity thresholds: a point moving
// at speed s for a time T sweeps a segment whose sphere has radius s T / 2.
#ifndef RIGID_BODY_SIM_PHYSICS_DYNAMICS_SLEEP_WINDOW_H_
#define RIGID_BODY_SIM_PHYSICS_DYNAMICS_SLEEP_WINDOW_H_

#include <array>

#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

struct SleepWindow {
  std::array<Vec3, 3> centers;    // m, world
  std::array<double, 3> radii{};  // m
  double time = -1.0;             // s the points have stayed within the limit; < 0: not started
};

struct SleepWindowLimits {
  double lever = 0.5;       // m, d: how far the two off-centre points are from the centre of mass
  double max_radius = 0.0;  // m, r
};

// The limits that match the velocity thresholds of sleep over time_to_sleep
// (m/s, rad/s, s; all > 0).
SleepWindowLimits MakeSleepWindowLimits(double linear_velocity, double angular_velocity,
                                        double time_to_sleep);

// Takes in the pose of the body's principal frame after a step of dt
// seconds and returns how long (s) its points have stayed within the limit.
double UpdateSleepWindow(const Pose& world_from_principal, const SleepWindowLimits& limits,
                         double dt, SleepWindow* window);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_DYNAMICS_SLEEP_WINDOW_H_
