// Basic math types and handles of the physics core. SI units throughout:
// metres, kilograms, seconds, radians.
#ifndef RIGID_BODY_SIM_PHYSICS_TYPES_H_
#define RIGID_BODY_SIM_PHYSICS_TYPES_H_

#include <cstdint>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rigid_body_sim::physics {

inline constexpr double kPi = 3.14159265358979323846;

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

// A rigid transform: `Pose a_from_b` maps coordinates in frame b to frame a,
// p_a = rotation * p_b + translation.
struct Pose {
  Vec3 translation = Vec3::Zero();   // m
  Quat rotation = Quat::Identity();  // unit quaternion

  static Pose Identity() { return Pose{}; }
  Vec3 operator*(const Vec3& p) const { return rotation * p + translation; }
  Pose operator*(const Pose& other) const {
    return Pose{rotation * other.translation + translation, rotation * other.rotation};
  }
  Pose Inverse() const {
    const Quat inverse_rotation = rotation.conjugate();
    return Pose{-(inverse_rotation * translation), inverse_rotation};
  }
};

// Handle to a body in a World. The generation makes a handle to a destroyed
// body invalid even after its slot is reused.
struct BodyId {
  static constexpr std::uint32_t kInvalidIndex = std::numeric_limits<std::uint32_t>::max();
  std::uint32_t index = kInvalidIndex;
  std::uint32_t generation = 0;

  bool IsValid() const { return index != kInvalidIndex; }
  friend bool operator==(BodyId a, BodyId b) {
    return a.index == b.index && a.generation == b.generation;
  }
  friend bool operator!=(BodyId a, BodyId b) { return !(a == b); }
};

// m x for a 3x3 m, written out: in hot loops GCC leaves Eigen's general
// product path as a call per use, which costs more than the product.
inline Vec3 Multiply(const Mat3& m, const Vec3& x) {
  return Vec3(m(0, 0) * x[0] + m(0, 1) * x[1] + m(0, 2) * x[2],
              m(1, 0) * x[0] + m(1, 1) * x[1] + m(1, 2) * x[2],
              m(2, 0) * x[0] + m(2, 1) * x[1] + m(2, 2) * x[2]);
}

inline bool IsFinite(const Vec3& v) { return v.allFinite(); }
inline bool IsFinite(const Quat& q) { return q.coeffs().allFinite(); }

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_TYPES_H_
