// WideBoxTree: the top-down build and the ray's single-precision setup.
#include "physics/geometry/wide_box_tree.h"

#include <algorithm>
#include <utility>

namespace rigid_body_sim::physics {
namespace {

// The query's margin as a fraction of the scale S = |bounds| + |origin|
// (max norms). Rounding moves a plane crossing by at most about 4 * 2^-24
// * S in position: the origin and the shifted bound rounded to float, then
// the product with the rounded 1/d (Higham 2002, Accuracy and Stability of
// Numerical Algorithms, section 2.2). A margin four times that keeps every
// box a double query meets.
constexpr double kMarginFraction = 0x1p-20;
// Inverses beyond this are clamped, so that a product never makes 0 * inf:
// a ray that slow along an axis crosses its planes beyond any reach a
// caller can use (t > 1e30 * margin).
constexpr double kLargestInverse = 1e30;
constexpr double kLargestFloat = std::numeric_limits<float>::max();

Aabb RangeBox(const std::vector<Aabb>& boxes, const std::vector<int>& order, int begin, int end) {
  Aabb box = boxes[order[begin]];
  for (int i = begin + 1; i < end; ++i) box = box.Union(boxes[order[i]]);
  return box;
}

// Splits [begin, end) at the median of the items' centres along the
// longest axis of their box (Ericson 2005, Real-Time Collision Detection,
// section 6.2.1).
int SplitAtMedian(const std::vector<Vec3>& centres, std::vector<int>* order, int begin, int end) {
  Vec3 lower = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 upper = -lower;
  for (int i = begin; i < end; ++i) {
    lower = lower.cwiseMin(centres[(*order)[i]]);
    upper = upper.cwiseMax(centres[(*order)[i]]);
  }
  int axis = 0;
  (upper - lower).maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(order->begin() + begin, order->begin() + middle, order->begin() + end,
                   [&](int x, int y) { return centres[x][axis] < centres[y][axis]; });
  return middle;
}

}  // namespace

WideBoxTree WideBoxTree::Build(const std::vector<Aabb>& boxes, int leaf_size,
                               std::vector<int>* order) {
  return Build(boxes, BuildSettings{leaf_size, leaf_size, nullptr}, order);
}

WideBoxTree WideBoxTree::Build(const std::vector<Aabb>& boxes, const BuildSettings& settings,
                               std::vector<int>* order) {
  assert(settings.leaf_size >= 1 && settings.median_split_above >= settings.leaf_size);
  assert(settings.centres == nullptr || settings.centres->size() == boxes.size());
  WideBoxTree tree;
  order->resize(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) (*order)[i] = static_cast<int>(i);
  if (boxes.empty()) return tree;
  std::vector<Vec3> box_centres;
  if (settings.centres == nullptr) {
    box_centres.resize(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      box_centres[i] = 0.5 * (boxes[i].min + boxes[i].max);
    }
  }
  const std::vector<Vec3>& centres = settings.centres ? *settings.centres : box_centres;
  tree.bounds_ = RangeBox(boxes, *order, 0, static_cast<int>(boxes.size()));
  tree.scale_ =
      std::max(tree.bounds_.min.cwiseAbs().maxCoeff(), tree.bounds_.max.cwiseAbs().maxCoeff());
  tree.nodes_.reserve(boxes.size() / settings.leaf_size + 1);
  tree.BuildNode(BuildInput{boxes, centres, settings}, 0, static_cast<int>(boxes.size()), order);
  return tree;
}

// A node's children: its range halved, then the larger halves halved
// again, until four ranges or every range fits a leaf; a range larger than
// a leaf becomes an inner child, built depth first. Each range is split as
// a binary median split would split it, so a mesh's triangles keep the
// order its binary tree gave them.
int WideBoxTree::BuildNode(const BuildInput& input, int begin, int end, std::vector<int>* order) {
  const std::vector<Aabb>& boxes = input.boxes;
  const int leaf_size = input.settings.leaf_size;
  std::vector<std::pair<int, int>> ranges{{begin, end}};
  while (static_cast<int>(ranges.size()) < kWidth) {
    auto largest = std::max_element(ranges.begin(), ranges.end(), [](const auto& a, const auto& b) {
      return a.second - a.first < b.second - b.first;
    });
    if (largest->second - largest->first <= leaf_size) break;
    const auto [first, last] = *largest;
    const int middle = last - first > input.settings.median_split_above
                           ? SplitAtMedian(input.centres, order, first, last)
                           : first + (last - first) / 2;
    *largest = {first, middle};
    ranges.insert(largest + 1, {middle, last});
  }
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  for (int i = 0; i < kWidth; ++i) {
    const bool used = i < static_cast<int>(ranges.size());
    const Aabb box = used ? RangeBox(boxes, *order, ranges[i].first, ranges[i].second) : Aabb{};
    for (int axis = 0; axis < 3; ++axis) {
      nodes_[index].lower[axis][i] = used ? RoundDown(box.min[axis]) : 0.0f;
      nodes_[index].upper[axis][i] = used ? RoundUp(box.max[axis]) : 0.0f;
    }
    nodes_[index].first[i] = used ? ranges[i].first : 0;
    nodes_[index].count[i] = used ? ranges[i].second - ranges[i].first : -1;
  }
  for (int i = 0; i < static_cast<int>(ranges.size()); ++i) {
    const auto [first, last] = ranges[i];
    if (last - first <= leaf_size) continue;
    const int child = BuildNode(input, first, last, order);
    nodes_[index].first[i] = child;
    nodes_[index].count[i] = 0;
  }
  return index;
}

WideBoxTree::FloatRay WideBoxTree::PrepareRay(const Vec3& origin, const Vec3& direction) const {
  const double scale = scale_ + origin.cwiseAbs().maxCoeff();
  const double margin = kMarginFraction * scale + std::numeric_limits<float>::min();
  FloatRay ray;
  for (int axis = 0; axis < 3; ++axis) {
    // Rounded to nearest, which the margin covers; clamped first, as a
    // conversion beyond float's range is undefined.
    ray.shift_lower[axis] =
        static_cast<float>(std::clamp(-origin[axis] - margin, -kLargestFloat, kLargestFloat));
    ray.shift_upper[axis] =
        static_cast<float>(std::clamp(-origin[axis] + margin, -kLargestFloat, kLargestFloat));
    const double d = direction[axis];
    const double inverse = 1.0 / (d != 0.0 ? d : std::copysign(1e-300, d));
    ray.inverse[axis] = static_cast<float>(std::clamp(inverse, -kLargestInverse, kLargestInverse));
  }
  return ray;
}

}  // namespace rigid_body_sim::physics
