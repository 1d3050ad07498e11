// Four doubles in the lanes of one SIMD vector, for the solvers' row
// updates that run several independent rows at once: the exact solver's
// batches (resting_batches.h) and the soft step's colour blocks
// (soft_contact_lanes.h). Each lane does its row's floating-point operations
// in the scalar update's order, with no fused multiply-add, so a lane gives
// the scalar result bit for bit.
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_SIMD_LANES_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_SIMD_LANES_H_

#include <cstdint>

namespace rigid_body_sim::physics {

inline constexpr int kBatchLanes = 4;

// Four doubles, one per lane (the vector extension of GCC and Clang:
// arithmetic and comparisons lane by lane, IEEE in each), aligned to their
// size in every translation unit: without AVX, GCC would align them to 16
// bytes only, where the AVX build of the sweep loads them aligned to 32.
using LaneDoubles = double __attribute__((vector_size(8 * kBatchLanes), aligned(8 * kBatchLanes)));
// All bits set in a lane where a comparison holds.
using LaneMask =
    std::int64_t __attribute__((vector_size(8 * kBatchLanes), aligned(8 * kBatchLanes)));

// Four floats, one per lane: what a solver only reads, stored at half the
// size (the soft step's compact blocks, soft_contact_lanes.h). Each widens
// to a double exactly, so the lanes compute in double with the values that
// the scalar rows hold rounded the same way.
using LaneFloats = float __attribute__((vector_size(4 * kBatchLanes), aligned(4 * kBatchLanes)));

// Stored lanes as doubles: widened from floats, copied from doubles.
[[gnu::always_inline]] inline void Widen(const LaneFloats& f, LaneDoubles* out) {
  *out = __builtin_convertvector(f, LaneDoubles);
}
[[gnu::always_inline]] inline void Widen(const LaneDoubles& d, LaneDoubles* out) { *out = d; }

// (Overloads, not a template: a vector type's alignment attribute is lost
// in a template argument.)
[[gnu::always_inline]] inline void Widen(const LaneFloats (&stored)[3], LaneDoubles (&out)[3]) {
  for (int axis = 0; axis < 3; ++axis) Widen(stored[axis], &out[axis]);
}
[[gnu::always_inline]] inline void Widen(const LaneDoubles (&stored)[3], LaneDoubles (&out)[3]) {
  for (int axis = 0; axis < 3; ++axis) out[axis] = stored[axis];
}

// What a solver only reads is stored as LaneStored<kCompact>::Type:
// floats when compact, else doubles.
template <bool kCompact>
struct LaneStored {
  using Type = LaneDoubles;
};
template <>
struct LaneStored<true> {
  using Type = LaneFloats;
};

// out = a . b, added left to right as Eigen adds a 3-vector's products.
[[gnu::always_inline]] inline void Dot(const LaneDoubles (&a)[3], const LaneDoubles (&b)[3],
                                       LaneDoubles* out) {
  *out = (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2];
}

// out = a x b, with the operations of Eigen's cross product of 3-vectors in
// its order, so a lane gives the bits of the scalar rows' products.
[[gnu::always_inline]] inline void Cross(const LaneDoubles (&a)[3], const LaneDoubles (&b)[3],
                                         LaneDoubles (&out)[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

// Whether any lane of `mask` is set.
[[gnu::always_inline]] inline bool AnyLane(const LaneMask& mask) {
  bool any = false;
  for (int lane = 0; lane < kBatchLanes; ++lane) any |= mask[lane] != 0;
  return any;
}

}  // namespace rigid_body_sim::physics

// The entry points of the lane updates, compiled twice on x86-64: for AVX2
// and for the baseline, chosen when the program loads (GCC's function
// multi-versioning). Without AVX2, the compiler lowers 32-byte vectors'
// comparisons to scalar branches. ThreadSanitizer instruments the generated
// ifunc resolver, which the loader runs before the sanitizer's runtime is
// up, so a TSan build (and any non-x86 target) gets the one baseline version.
#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define RBS_THREAD_SANITIZER 1
#endif
#endif
#if defined(__x86_64__) && !defined(__SANITIZE_THREAD__) && !defined(RBS_THREAD_SANITIZER)
#define RBS_SIMD_CLONES [[gnu::target_clones("avx2", "default")]]
#else
#define RBS_SIMD_CLONES
#endif

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_SIMD_LANES_H_
