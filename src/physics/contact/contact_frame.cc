#include "physics/contact/contact_frame.h"

#include <algorithm>
#include <cmath>

namespace rigid_body_sim::physics {

std::array<Vec3, 2> TangentBasis(const Vec3& normal) {
  const Vec3 helper = std::abs(normal.x()) < 0.57 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 t1 = normal.cross(helper).normalized();
  return {t1, normal.cross(t1)};
}

double CombineRestitution(double restitution_a, double restitution_b) {
  return std::max(restitution_a, restitution_b);
}

double CombineFriction(double friction_a, double friction_b) {
  return std::sqrt(friction_a * friction_b);
}

}  // namespace rigid_body_sim::physics
