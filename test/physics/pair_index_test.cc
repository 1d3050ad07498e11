// PairIndex against std::unordered_map, the reference: the same random
// inserts, erases and lookups must give the same answers, through growth
// and long runs of backward-shift deletions. And the contact cache's key
// sort (SortByPairKey) against std::sort, its reference.
#include "physics/collision/pair_index.h"

#include <algorithm>
#include <cstdint>
#include <random>
#include <unordered_map>
#include <vector>

#include <gtest/gtest.h>

#include "physics/contact/contact_cache.h"

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

// Distinct keys laid out as the cache's (body A << 44 | body B << 24 |
// shapes), in random, reversed and sorted order, with bodies that have one
// pair, many pairs or none: the counting sort gives std::sort's order.
TEST(PairIndexTest, SortByPairKeyGivesStdSortsOrder) {
  std::mt19937_64 random(11);
  std::vector<KeyedPair> scratch;
  std::vector<std::uint32_t> starts;
  for (const std::size_t count : {0u, 1u, 2u, 7u, 300u, 5000u}) {
    for (const std::uint64_t bodies : {1u, 3u, 1000u, (1u << 20) - 1}) {
      std::vector<std::uint64_t> keys;
      for (std::size_t k = 0; k < count; ++k) {
        keys.push_back(((random() % bodies) << 44) | ((random() % bodies) << 24) |
                       (random() % 4096) << 12 | random() % 4096);
      }
      std::sort(keys.begin(), keys.end());
      keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
      std::vector<KeyedPair> expected;
      for (const std::uint64_t key : keys) {
        expected.emplace_back(key, reinterpret_cast<ShapePairContact*>(key + 1));
      }
      for (int order = 0; order < 3; ++order) {
        std::vector<KeyedPair> keyed = expected;
        if (order == 0) std::shuffle(keyed.begin(), keyed.end(), random);
        if (order == 1) std::reverse(keyed.begin(), keyed.end());
        SortByPairKey(&keyed, &scratch, &starts);
        ASSERT_EQ(keyed, expected) << count << " keys, " << bodies << " bodies, order " << order;
      }
    }
  }
}

}  // namespace
}  // namespace rigid_body_sim::physics
