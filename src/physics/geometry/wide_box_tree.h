// A four-wide tree of axis-aligned boxes whose bounds are stored in single
// precision, rounded outward, and tested four children at a time: the
// static meshes' tree (triangles) and the ray-cast batch's tree (shapes).
//
// Why four-wide and single precision: a ray walking a binary tree of
// double boxes spends most of its time fetching 56-byte nodes and testing
// one box per branch. Four children per node halve the depth, and their
// boxes fit in two cache lines and one SIMD test (Wald, Benthin and
// Boulos 2008, "Getting Rid of Packets: Efficient SIMD Single-Ray
// Traversal using Multi-branching BVHs", section 3; Dammertz, Hanika and
// Keller 2008, "Shallow Bounding Volume Hierarchies for Fast SIMD Ray
// Tracing of Incoherent Rays").
//
// Why the answers stay exact: the tree only chooses what to test. Every box
// is rounded outward when stored, and every query widens its test by more
// than the rounding of single precision can move a plane (the robust slab
// test of Ize 2013, "Robust BVH Ray Traversal", JCGT 2(2), section 3, with
// the error bound taken in position rather than in t), so a box the exact
// query meets is never skipped; the items themselves are tested in double.
#ifndef RIGID_BODY_SIM_PHYSICS_GEOMETRY_WIDE_BOX_TREE_H_
#define RIGID_BODY_SIM_PHYSICS_GEOMETRY_WIDE_BOX_TREE_H_

#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "physics/geometry/aabb.h"

namespace rigid_body_sim::physics {

class WideBoxTree {
 public:
  static constexpr int kWidth = 4;
  // The builder halves ranges at their median, so the depth is at most
  // log4(items) + 2; 2^24 triangles take 14 levels, and a walk keeps at
  // most three pending children per level.
  static constexpr int kMaxDepth = 40;

  struct Node {
    // The children's boxes by axis and lane: lower[axis][child] (m).
    alignas(16) float lower[3][kWidth];
    alignas(16) float upper[3][kWidth];
    // An inner child: `first` is its node and `count` is 0. A leaf child:
    // items order[first, first + count). An empty slot: count -1.
    std::array<int, kWidth> first;
    std::array<int, kWidth> count;
  };

  // The tree over `boxes`, leaves of at most `leaf_size` items (>= 1).
  // `order` gets the items in tree order: a leaf's items are
  // order[first, first + count), consecutive, so a caller that stores its
  // items in this order reads a leaf from one stretch of memory.
  static WideBoxTree Build(const std::vector<Aabb>& boxes, int leaf_size, std::vector<int>* order);

  struct BuildSettings {
    int leaf_size = 1;  // items per leaf, at most, >= 1
    // Ranges of more items are split at their median; smaller ones are cut
    // in the middle as they stand (>= leaf_size). A mesh keeps the order of
    // a binary tree with leaves of this size, and tests smaller leaves.
    int median_split_above = 1;
    // The items' own centres (a triangle's centroid) to split by; null:
    // their boxes' centres.
    const std::vector<Vec3>* centres = nullptr;
  };
  static WideBoxTree Build(const std::vector<Aabb>& boxes, const BuildSettings& settings,
                           std::vector<int>* order);

  // The box of all the items (double, not rounded); zero when empty.
  const Aabb& bounds() const { return bounds_; }

  // Calls leaf(first, count) for the leaves the ray o + t d, 0 <= t <=
  // *reach, may enter, nearest entry first; a leaf may shorten *reach (to
  // its nearest hit), and a leaf entered beyond it is then skipped. Every
  // leaf holding an item whose box the exact ray meets within *reach is
  // called. `direction` need not be unit: t is in its units.
  template <class Leaf>
  void CastRay(const Vec3& origin, const Vec3& direction, double* reach, Leaf&& leaf) const;

  // Calls leaf(first, count) for every leaf whose box may overlap the
  // closed box `box` (every leaf holding an item whose box does).
  template <class Leaf>
  void QueryBox(const Aabb& box, Leaf&& leaf) const;

 private:
  // A ray prepared for the single-precision test: the slab planes of a box
  // [lower, upper] are crossed at t = (lower + shift_lower) * inverse and
  // (upper + shift_upper) * inverse, the shifts being -origin -+ a margin.
  struct FloatRay {
    float shift_lower[3];
    float shift_upper[3];
    float inverse[3];
  };
  FloatRay PrepareRay(const Vec3& origin, const Vec3& direction) const;
  static float RoundUp(double value);
  // A float at or above `reach` (t), cheaper than RoundUp: 1 + 2^-20
  // covers the conversion's relative error of 2^-24.
  static float ReachBound(double reach) {
    return reach < 1e38 ? static_cast<float>(reach) * (1.0f + 0x1p-20f) +
                              std::numeric_limits<float>::denorm_min()
                        : std::numeric_limits<float>::infinity();
  }
  static float RoundDown(double value);
  // The used lanes (bit i for child i) whose box the ray enters within
  // [0, reach]; entry[i] gets each lane's entry t.
  static int RayLanes(const Node& node, const FloatRay& ray, float reach, float* entry);
  static int BoxLanes(const Node& node, const float* lower, const float* upper);
  struct BuildInput {
    const std::vector<Aabb>& boxes;
    const std::vector<Vec3>& centres;
    const BuildSettings& settings;
  };
  int BuildNode(const BuildInput& input, int begin, int end, std::vector<int>* order);

  std::vector<Node> nodes_;
  Aabb bounds_;
  // m: the largest |coordinate| of bounds_, the scale of the rounding.
  double scale_ = 0.0;
};

// The next float up by its bits: std::nextafter is a library call (in each
// ray's setup it cost a batch of 100,000 rays 15 % of its time).
inline float WideBoxTree::RoundUp(double value) {
  if (!(value < std::numeric_limits<float>::max())) return std::numeric_limits<float>::infinity();
  if (value <= -std::numeric_limits<float>::max()) return -std::numeric_limits<float>::max();
  float f = static_cast<float>(value);
  if (static_cast<double>(f) >= value) return f;
  if (f == 0.0f) return std::numeric_limits<float>::denorm_min();
  std::uint32_t bits;
  std::memcpy(&bits, &f, sizeof(bits));
  bits = f > 0.0f ? bits + 1 : bits - 1;  // a larger magnitude above 0, a smaller below
  std::memcpy(&f, &bits, sizeof(f));
  return f;
}

inline float WideBoxTree::RoundDown(double value) { return -RoundUp(-value); }

inline int WideBoxTree::RayLanes(const Node& node, const FloatRay& ray, float reach, float* entry) {
#if defined(__SSE2__)
  __m128 enter = _mm_setzero_ps();
  __m128 leave = _mm_set1_ps(reach);
  for (int axis = 0; axis < 3; ++axis) {
    const __m128 inverse = _mm_set1_ps(ray.inverse[axis]);
    const __m128 t1 = _mm_mul_ps(
        _mm_add_ps(_mm_load_ps(node.lower[axis]), _mm_set1_ps(ray.shift_lower[axis])), inverse);
    const __m128 t2 = _mm_mul_ps(
        _mm_add_ps(_mm_load_ps(node.upper[axis]), _mm_set1_ps(ray.shift_upper[axis])), inverse);
    enter = _mm_max_ps(enter, _mm_min_ps(t1, t2));
    leave = _mm_min_ps(leave, _mm_max_ps(t1, t2));
  }
  _mm_storeu_ps(entry, enter);
  const __m128i used = _mm_cmpgt_epi32(
      _mm_loadu_si128(reinterpret_cast<const __m128i*>(node.count.data())), _mm_set1_epi32(-1));
  return _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(enter, leave), _mm_castsi128_ps(used)));
#else
  int lanes = 0;
  for (int i = 0; i < kWidth; ++i) {
    float enter = 0.0f;
    float leave = reach;
    for (int axis = 0; axis < 3; ++axis) {
      const float t1 = (node.lower[axis][i] + ray.shift_lower[axis]) * ray.inverse[axis];
      const float t2 = (node.upper[axis][i] + ray.shift_upper[axis]) * ray.inverse[axis];
      enter = std::max(enter, std::min(t1, t2));
      leave = std::min(leave, std::max(t1, t2));
    }
    entry[i] = enter;
    if (enter <= leave && node.count[i] >= 0) lanes |= 1 << i;
  }
  return lanes;
#endif
}

inline int WideBoxTree::BoxLanes(const Node& node, const float* lower, const float* upper) {
  int lanes = (1 << kWidth) - 1;
  for (int axis = 0; axis < 3; ++axis) {
    for (int i = 0; i < kWidth; ++i) {
      if (!(node.lower[axis][i] <= upper[axis] && lower[axis] <= node.upper[axis][i])) {
        lanes &= ~(1 << i);
      }
    }
  }
  return lanes;
}

// The walk descends into the nearest entered child at once and keeps the
// others on a stack, nearest on top, in three plain arrays (a stack of
// structs stalled on store-to-load forwarding: 15 % of the walk).
template <class Leaf>
void WideBoxTree::CastRay(const Vec3& origin, const Vec3& direction, double* reach,
                          Leaf&& leaf) const {
  if (nodes_.empty()) return;
  const FloatRay ray = PrepareRay(origin, direction);
  float reach_up = ReachBound(*reach);
  constexpr int kStack = 3 * kMaxDepth + 1;
  int stack_first[kStack];
  int stack_count[kStack];
  float stack_entry[kStack];
  int size = 0;
  int first = 0;  // the root
  int count = 0;
  for (;;) {
    if (count > 0) {
      leaf(first, count);
      reach_up = ReachBound(*reach);
    } else {
      const Node& node = nodes_[first];
      // The node's second cache line (first, count) is asked for with its
      // first (the bounds), not after their test.
      __builtin_prefetch(&node.first);
      float entry[kWidth];
      int lanes = RayLanes(node, ray, reach_up, entry);
      // Most nodes of a walk have one entered child (78 % on a terrain):
      // straight into it, without the sort and its branches.
      if (lanes != 0 && (lanes & (lanes - 1)) == 0) {
        const int lane = __builtin_ctz(static_cast<unsigned>(lanes));
        first = node.first[lane];
        count = node.count[lane];
        continue;
      }
      // The entered children by entry, nearest last (an insertion sort of
      // at most four).
      int sorted[kWidth];
      int n = 0;
      for (; lanes != 0; lanes &= lanes - 1) {
        const int lane = __builtin_ctz(static_cast<unsigned>(lanes));
        int j = n++;
        for (; j > 0 && entry[sorted[j - 1]] < entry[lane]; --j) sorted[j] = sorted[j - 1];
        sorted[j] = lane;
      }
      if (n > 0) {
        assert(size + n - 1 <= kStack);
        for (int k = 0; k < n - 1; ++k) {
          stack_first[size] = node.first[sorted[k]];
          stack_count[size] = node.count[sorted[k]];
          stack_entry[size] = entry[sorted[k]];
          ++size;
        }
        first = node.first[sorted[n - 1]];
        count = node.count[sorted[n - 1]];
        continue;
      }
    }
    do {
      if (size == 0) return;
      --size;
    } while (stack_entry[size] > reach_up);
    first = stack_first[size];
    count = stack_count[size];
  }
}

// Depth first, children in order, so the leaves come in the order of the
// items (a caller's output keeps one order whatever the tree's width).
template <class Leaf>
void WideBoxTree::QueryBox(const Aabb& box, Leaf&& leaf) const {
  if (nodes_.empty()) return;
  float lower[3];
  float upper[3];
  for (int axis = 0; axis < 3; ++axis) {
    lower[axis] = RoundDown(box.min[axis]);
    upper[axis] = RoundUp(box.max[axis]);
  }
  constexpr int kStack = 3 * kMaxDepth + 1;
  int stack_first[kStack];
  int stack_count[kStack];
  int size = 0;
  stack_first[size] = 0;
  stack_count[size] = 0;
  ++size;
  while (size > 0) {
    --size;
    if (stack_count[size] > 0) {
      leaf(stack_first[size], stack_count[size]);
      continue;
    }
    const Node& node = nodes_[stack_first[size]];
    const int lanes = BoxLanes(node, lower, upper);
    for (int i = kWidth - 1; i >= 0; --i) {
      if (!(lanes >> i & 1) || node.count[i] < 0) continue;
      assert(size < kStack);
      stack_first[size] = node.first[i];
      stack_count[size] = node.count[i];
      ++size;
    }
  }
}

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_GEOMETRY_WIDE_BOX_TREE_H_
