// A hash of a world's state bit for bit, for the determinism tests.
#ifndef RIGID_BODY_SIM_TEST_PHYSICS_STATE_HASH_H_
#define RIGID_BODY_SIM_TEST_PHYSICS_STATE_HASH_H_

#include <cstdint>
#include <cstring>

#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics::testing {

// FNV-1a, 64 bits, over the bytes of doubles: a change in the last bit of
// any value changes the hash, which a sum or a norm of the state would not
// reliably do.
class StateHash {
 public:
  void Add(double value) {
    unsigned char bytes[sizeof(double)];
    std::memcpy(bytes, &value, sizeof(double));
    for (const unsigned char byte : bytes) {
      hash_ ^= byte;
      hash_ *= kPrime;
    }
  }
  void Add(const Vec3& v) {
    for (int i = 0; i < 3; ++i) Add(v[i]);
  }
  void Add(const Quat& q) {
    const Eigen::Vector4d coeffs = q.coeffs();
    for (int i = 0; i < 4; ++i) Add(coeffs[i]);
  }
  std::uint64_t value() const { return hash_; }

 private:
  static constexpr std::uint64_t kOffsetBasis = 14695981039346656037ULL;
  static constexpr std::uint64_t kPrime = 1099511628211ULL;
  std::uint64_t hash_ = kOffsetBasis;
};

}  // namespace rigid_body_sim::physics::testing

#endif  // RIGID_BODY_SIM_TEST_PHYSICS_STATE_HASH_H_
