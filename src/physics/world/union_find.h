// Disjoint sets of indices, for the islands of the contact graph: the solver
// sweeps each island to its own convergence, and the sleep test puts whole
// islands to sleep.
//
// Union by linking roots, with path halving in Find (Tarjan and van Leeuwen,
// "Worst-case analysis of set union algorithms", 1984).
#ifndef RIGID_BODY_SIM_PHYSICS_WORLD_UNION_FIND_H_
#define RIGID_BODY_SIM_PHYSICS_WORLD_UNION_FIND_H_

#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

namespace rigid_body_sim::physics {

class UnionFind {
 public:
  explicit UnionFind(std::size_t size = 0) { Reset(size); }

  // Makes every index its own set; keeps the memory.
  void Reset(std::size_t size) {
    parent_.resize(size);
    std::iota(parent_.begin(), parent_.end(), 0u);
  }

  // The root of i's set.
  std::uint32_t Find(std::uint32_t i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }

  void Join(std::uint32_t a, std::uint32_t b) { parent_[Find(a)] = Find(b); }

 private:
  std::vector<std::uint32_t> parent_;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_WORLD_UNION_FIND_H_
