#include "physics/solver/constraint_colouring.h"

#include <cassert>

namespace rigid_body_sim::physics {

void ColourConstraints(const std::vector<std::uint32_t>& body_a,
                       const std::vector<std::uint32_t>& body_b,
                       const std::vector<std::uint8_t>& moving, std::vector<std::uint32_t>* used,
                       std::vector<std::uint8_t>* colour_of, ConstraintColouring* colouring) {
  assert(body_a.size() == body_b.size());
  constexpr int kColours = ConstraintColouring::kMaxColours;
  constexpr std::uint8_t kOverflow = kColours;
  static_assert(kColours <= 32, "one 32-bit mask word per body");
  const std::size_t count = body_a.size();
  used->assign(moving.size(), 0u);
  colour_of->resize(count);
  std::vector<std::uint32_t>& mask = *used;
  // The colour sizes, then (prefix sums) where each colour starts.
  std::vector<std::uint32_t>& start = colouring->colour_start;
  start.assign(kColours + 2, 0u);
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t a = body_a[i];
    const std::uint32_t b = body_b[i];
    const std::uint32_t taken = (moving[a] ? mask[a] : 0u) | (moving[b] ? mask[b] : 0u);
    std::uint8_t colour = kOverflow;
    if (taken != ~0u) {
      for (int c = 0; c < kColours; ++c) {
        if ((taken & (1u << c)) == 0) {
          colour = static_cast<std::uint8_t>(c);
          break;
        }
      }
    }
    if (colour != kOverflow) {
      if (moving[a]) mask[a] |= 1u << colour;
      if (moving[b]) mask[b] |= 1u << colour;
    }
    (*colour_of)[i] = colour;
    ++start[colour + 1];
  }
  // Drop the empty colours at the end (the overflow stays last).
  int last = kColours - 1;
  while (last >= 0 && start[last + 1] == 0) --last;
  const std::uint32_t overflow = start[kColours + 1];
  start.resize(last + 2);
  for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
  colouring->order.resize(count);
  std::vector<std::uint32_t> next(start.begin(), start.end());
  next.push_back(start.back());
  for (std::size_t i = 0; i < count; ++i) {
    const int colour = (*colour_of)[i] == kOverflow ? last + 1 : (*colour_of)[i];
    colouring->order[next[colour]++] = static_cast<std::uint32_t>(i);
  }
  assert(start.back() + overflow == count);
  (void)overflow;
}

}  // namespace rigid_body_sim::physics
