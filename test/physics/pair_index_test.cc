// PairIndex against std::unordered_map, the reference: the same random
// inserts, erases and lookups must give the same answers, through growth
// and long runs of backward-shift deletions.
#include "physics/collision/pair_index.h"

#include <cstdint>
#include <random>
#include <unordered_map>
#include <vector>

#include <gtest/gtest.h>

namespace rigid_body_sim::physics {
namespace {

TEST(PairIndexTest, AgreesWithUnorderedMapUnderRandomChurn) {
  std::mt19937_64 random(7);
  std::vector<int> values(4096);
  PairIndex<int> index;
  std::unordered_map<std::uint64_t, int*> reference;
  // Keys shaped like the contact cache's (body indices in the high bits),
  // from a small range so that probe runs collide and wrap.
  auto random_key = [&random] {
    const std::uint64_t a = random() % 64;
    const std::uint64_t b = random() % 64;
    return (a << 44) | (b << 24) | (random() % 2);
  };
  for (int op = 0; op < 200000; ++op) {
    const std::uint64_t key = random_key();
    const auto it = reference.find(key);
    switch (random() % 3) {
      case 0:
        if (it == reference.end()) {
          int* value = &values[random() % values.size()];
          index.Insert(key, value);
          reference.emplace(key, value);
        }
        break;
      case 1:
        index.Erase(key);
        reference.erase(key);
        break;
      default:
        break;
    }
    const auto after = reference.find(key);
    ASSERT_EQ(index.Find(key), after == reference.end() ? nullptr : after->second) << "op " << op;
    ASSERT_EQ(index.size(), reference.size()) << "op " << op;
  }
  // Every key of the range, present or not, once more at the end.
  for (std::uint64_t a = 0; a < 64; ++a) {
    for (std::uint64_t b = 0; b < 64; ++b) {
      for (std::uint64_t s = 0; s < 2; ++s) {
        const std::uint64_t key = (a << 44) | (b << 24) | s;
        const auto it = reference.find(key);
        EXPECT_EQ(index.Find(key), it == reference.end() ? nullptr : it->second);
      }
    }
  }
  index.Clear();
  EXPECT_EQ(index.size(), 0u);
  for (const auto& [key, value] : reference) EXPECT_EQ(index.Find(key), nullptr);
}

}  // namespace
}  // namespace rigid_body_sim::physics
