// An open-addressing index from 64-bit pair keys to pointers, for the
// contact cache's per-visit lookup: one multiply and, at a load of at most
// one half, about one probe of a contiguous array, where a node-based hash
// map pays a division and two dependent loads.
//
// Linear probing with Fibonacci hashing (Knuth, TAOCP vol. 3, 6.4) and
// deletion by backward shift (no tombstones, so probe lengths do not grow
// with churn). Tested against std::unordered_map in pair_index_test.cc.
#ifndef RIGID_BODY_SIM_PHYSICS_COLLISION_PAIR_INDEX_H_
#define RIGID_BODY_SIM_PHYSICS_COLLISION_PAIR_INDEX_H_

#include <cstddef>
#include <cstdint>
#include <vector>

namespace rigid_body_sim::physics {

template <typename T>
class PairIndex {
 public:
  // The key no pair has; inserting it is a programmer error.
  static constexpr std::uint64_t kEmptyKey = ~std::uint64_t{0};

  // The value of `key`, or nullptr.
  T* Find(std::uint64_t key) const {
    if (slots_.empty()) return nullptr;
    for (std::size_t i = Home(key);; i = (i + 1) & mask_) {
      if (slots_[i].key == key) return slots_[i].value;
      if (slots_[i].key == kEmptyKey) return nullptr;
    }
  }

  // Starts loading the slot where a lookup of `key` begins, for a Find
  // soon after: the index is larger than the caches, and a lookup that
  // waits for its slot is the contact cache's main cost.
  void PrefetchSlot(std::uint64_t key) const {
    if (!slots_.empty()) __builtin_prefetch(&slots_[Home(key)]);
  }

  // Adds `key`, which must be absent, with `value`.
  void Insert(std::uint64_t key, T* value) {
    if (2 * (size_ + 1) > slots_.size()) Grow();
    std::size_t i = Home(key);
    while (slots_[i].key != kEmptyKey) i = (i + 1) & mask_;
    slots_[i] = Slot{key, value};
    ++size_;
  }

  // Removes `key` if present. Later entries of its probe run move back into
  // the hole unless their home lies cyclically in (hole, entry].
  void Erase(std::uint64_t key) {
    if (slots_.empty()) return;
    std::size_t hole = Home(key);
    while (slots_[hole].key != key) {
      if (slots_[hole].key == kEmptyKey) return;
      hole = (hole + 1) & mask_;
    }
    for (std::size_t i = (hole + 1) & mask_; slots_[i].key != kEmptyKey; i = (i + 1) & mask_) {
      const std::size_t home = Home(slots_[i].key);
      const bool stays = ((i - home) & mask_) < ((i - hole) & mask_);
      if (stays) continue;
      slots_[hole] = slots_[i];
      hole = i;
    }
    slots_[hole] = Slot{};
    --size_;
  }

  void Clear() {
    for (Slot& slot : slots_) slot = Slot{};
    size_ = 0;
  }

  std::size_t size() const { return size_; }

 private:
  struct Slot {
    std::uint64_t key = kEmptyKey;
    T* value = nullptr;
  };

  std::size_t Home(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9e3779b97f4a7c15ull) >> shift_);
  }

  void Grow() {
    std::vector<Slot> old;
    old.swap(slots_);
    const std::size_t capacity = old.empty() ? 64 : 2 * old.size();
    slots_.assign(capacity, Slot{});
    mask_ = capacity - 1;
    shift_ = 64;
    for (std::size_t c = capacity; c > 1; c >>= 1) --shift_;
    size_ = 0;
    for (const Slot& slot : old) {
      if (slot.key != kEmptyKey) Insert(slot.key, slot.value);
    }
  }

  std::vector<Slot> slots_;  // capacity a power of two
  std::size_t mask_ = 0;
  int shift_ = 64;  // 64 - log2(capacity)
  std::size_t size_ = 0;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_COLLISION_PAIR_INDEX_H_
