#include "physics/dynamics/sleep_window.h"

#include <cassert>

namespace rigid_body_sim::physics {
namespace {

std::array<Vec3, 3> WindowPoints(const Pose& world_from_principal, double lever) {
  const Mat3 rotation = world_from_principal.rotation.toRotationMatrix();
  const Vec3& centre = world_from_principal.translation;
  return {centre, centre + lever * rotation.col(0), centre + lever * rotation.col(1)};
}

// Ritter's step: the smallest sphere holding the old sphere and the point.
void TakeIn(const Vec3& point, Vec3* centre, double* radius) {
  const Vec3 offset = point - *centre;
  const double distance = offset.norm();
  if (distance <= *radius) return;
  const double grown = 0.5 * (*radius + distance);
  *centre += ((grown - *radius) / distance) * offset;
  *radius = grown;
}

}  // namespace

SleepWindowLimits MakeSleepWindowLimits(double linear_velocity, double angular_velocity,
                                        double time_to_sleep) {
  assert(linear_velocity > 0.0 && angular_velocity > 0.0 && time_to_sleep > 0.0);
  SleepWindowLimits limits;
  limits.lever = linear_velocity / angular_velocity;
  limits.max_radius = 0.5 * linear_velocity * time_to_sleep;
  return limits;
}

double UpdateSleepWindow(const Pose& world_from_principal, const SleepWindowLimits& limits,
                         double dt, SleepWindow* window) {
  const std::array<Vec3, 3> points = WindowPoints(world_from_principal, limits.lever);
  bool within = window->time >= 0.0;
  for (int i = 0; i < 3 && within; ++i) {
    TakeIn(points[i], &window->centers[i], &window->radii[i]);
    within = window->radii[i] <= limits.max_radius;
  }
  if (!within) {
    window->centers = points;
    window->radii = {0.0, 0.0, 0.0};
    window->time = 0.0;
    return 0.0;
  }
  window->time += dt;
  return window->time;
}

}  // namespace rigid_body_sim::physics
