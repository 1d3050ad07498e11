#include "physics/collision/broad_phase.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "physics/geometry/aabb.h"
#include "support/brute_force_broad_phase.h"

namespace rigid_body_sim::physics {
namespace {

Aabb Box(double x0, double y0, double z0, double x1, double y1, double z1) {
  return Aabb{Vec3(x0, y0, z0), Vec3(x1, y1, z1)};
}

Aabb UnitCubeAt(const Vec3& min_corner) { return Aabb{min_corner, min_corner + Vec3::Ones()}; }

// Empty when equal; otherwise names the first pairs that differ.
std::string DescribeDifference(const std::vector<ProxyPair>& actual,
                               const std::vector<ProxyPair>& expected) {
  std::ostringstream out;
  std::size_t i = 0;
  std::size_t j = 0;
  int reported = 0;
  while ((i < actual.size() || j < expected.size()) && reported < 5) {
    if (j == expected.size() || (i < actual.size() && actual[i] < expected[j])) {
      out << " extra (" << actual[i].first << ", " << actual[i].second << ")";
      ++i;
      ++reported;
    } else if (i == actual.size() || expected[j] < actual[i]) {
      out << " missing (" << expected[j].first << ", " << expected[j].second << ")";
      ++j;
      ++reported;
    } else {
      ++i;
      ++j;
    }
  }
  return out.str();
}

TEST(AabbTest, OverlapUsesClosedIntervalsOnAllThreeAxes) {
  const Aabb a = Box(0, 0, 0, 1, 1, 1);
  EXPECT_TRUE(a.Overlaps(Box(0.5, 0.5, 0.5, 2, 2, 2)));
  EXPECT_TRUE(a.Overlaps(Box(1, 0, 0, 2, 1, 1)));  // shared face x = 1
  EXPECT_TRUE(a.Overlaps(Box(1, 1, 1, 2, 2, 2)));  // shared corner
  const double just_past_one = std::nextafter(1.0, 2.0);
  EXPECT_FALSE(a.Overlaps(Box(just_past_one, 0, 0, 2, 1, 1)));
  EXPECT_FALSE(a.Overlaps(Box(0.5, 0.5, 2, 2, 2, 3)));  // x and y only
  EXPECT_TRUE(a.OverlapsOnAxis(Box(0.5, 0.5, 2, 2, 2, 3), 1));
  EXPECT_FALSE(a.OverlapsOnAxis(Box(0.5, 0.5, 2, 2, 2, 3), 2));
}

TEST(AabbTest, UnionAndFattened) {
  const Aabb merged = Box(0, 1, 2, 1, 2, 3).Union(Box(-1, 1.5, 2.5, 0.5, 4, 2.75));
  EXPECT_EQ(merged.min, Vec3(-1, 1, 2));
  EXPECT_EQ(merged.max, Vec3(1, 4, 3));
  const Aabb fat = Box(0, 1, 2, 1, 2, 3).Fattened(0.25);
  EXPECT_EQ(fat.min, Vec3(-0.25, 0.75, 1.75));
  EXPECT_EQ(fat.max, Vec3(1.25, 2.25, 3.25));
}

TEST(AabbTest, ValidityRequiresFiniteCornersAndOrderedBounds) {
  EXPECT_TRUE(Box(0, 0, 0, 0, 1, 1).IsValid());  // flat box
  EXPECT_FALSE(Box(0, 0, 0, 1, -1, 1).IsValid());
  EXPECT_FALSE(Box(0, std::nan(""), 0, 1, 1, 1).IsValid());
  EXPECT_FALSE(Box(0, 0, 0, 1, 1, std::numeric_limits<double>::infinity()).IsValid());
}

TEST(SortAndSweepBroadPhaseTest, PairNeedsOverlapOnAllThreeAxes) {
  SortAndSweepBroadPhase broad_phase;
  const int a = broad_phase.AddProxy(Box(0, 0, 0, 1, 1, 1), ProxyKind::kDynamic).value();
  const int x_only = broad_phase.AddProxy(Box(0.5, 2, 2, 1.5, 3, 3), ProxyKind::kDynamic).value();
  const int x_and_y =
      broad_phase.AddProxy(Box(0.5, 0.5, 5, 1.5, 1.5, 6), ProxyKind::kDynamic).value();
  const int all_three =
      broad_phase.AddProxy(Box(0.5, 0.5, 0.5, 1.5, 1.5, 1.5), ProxyKind::kDynamic).value();
  const int touching = broad_phase.AddProxy(Box(1, 0, 0, 2, 1, 1), ProxyKind::kDynamic).value();
  const int one_ulp_away =
      broad_phase.AddProxy(Box(-1, 0, 0, std::nextafter(0.0, -1.0), 1, 1), ProxyKind::kDynamic)
          .value();
  broad_phase.Update();
  // all_three also overlaps touching: x [0.5, 1.5] vs [1, 2], y and z [0.5, 1] shared.
  const std::vector<ProxyPair> expected = {{a, all_three}, {a, touching}, {all_three, touching}};
  EXPECT_EQ(broad_phase.Pairs(), expected);
  EXPECT_FALSE(broad_phase.HasPair(a, x_only));
  EXPECT_FALSE(broad_phase.HasPair(a, x_and_y));
  EXPECT_FALSE(broad_phase.HasPair(a, one_ulp_away));
  EXPECT_TRUE(broad_phase.HasPair(touching, a));

  // Incremental: the x-only box drops onto a's y and z range, then leaves on x.
  ASSERT_TRUE(broad_phase.SetAabb(x_only, Box(0.5, 0.25, 0.25, 1.5, 0.75, 0.75)).ok());
  broad_phase.Update();
  EXPECT_TRUE(broad_phase.HasPair(a, x_only));
  EXPECT_TRUE(broad_phase.HasPair(all_three, x_only));
  EXPECT_TRUE(broad_phase.HasPair(touching, x_only));
  EXPECT_EQ(broad_phase.PairCount(), 6u);
  ASSERT_TRUE(broad_phase.SetAabb(x_only, Box(3, 0.25, 0.25, 4, 0.75, 0.75)).ok());
  broad_phase.Update();
  EXPECT_EQ(broad_phase.Pairs(), expected);
}

TEST(SortAndSweepBroadPhaseTest, StaticAndSleepingPairsFollowTheRules) {
  SortAndSweepBroadPhase broad_phase;
  // All four boxes overlap each other.
  const int static_a = broad_phase.AddProxy(UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kStatic).value();
  const int static_b =
      broad_phase.AddProxy(UnitCubeAt(Vec3(0.5, 0, 0)), ProxyKind::kStatic).value();
  const int sleeping_a =
      broad_phase.AddProxy(UnitCubeAt(Vec3(0, 0.5, 0)), ProxyKind::kSleeping).value();
  const int sleeping_b =
      broad_phase.AddProxy(UnitCubeAt(Vec3(0, 0, 0.5)), ProxyKind::kSleeping).value();
  broad_phase.Update();
  EXPECT_EQ(broad_phase.PairCount(), 0u);  // static-static, static-sleeping, sleeping-sleeping

  // Waking one sleeper pairs it with the other three.
  ASSERT_TRUE(broad_phase.SetKind(sleeping_a, ProxyKind::kDynamic).ok());
  broad_phase.Update();
  std::vector<ProxyPair> expected = {
      {static_a, sleeping_a}, {static_b, sleeping_a}, {sleeping_a, sleeping_b}};
  EXPECT_EQ(broad_phase.Pairs(), expected);

  // Two dynamic boxes: the pair between them survives when one falls asleep.
  ASSERT_TRUE(broad_phase.SetKind(sleeping_b, ProxyKind::kDynamic).ok());
  broad_phase.Update();
  EXPECT_EQ(broad_phase.PairCount(), 5u);
  ASSERT_TRUE(broad_phase.SetKind(sleeping_a, ProxyKind::kSleeping).ok());
  broad_phase.Update();
  expected = {{static_a, sleeping_b}, {static_b, sleeping_b}, {sleeping_a, sleeping_b}};
  EXPECT_EQ(broad_phase.Pairs(), expected);

  // A static box made static again (or sleeping) keeps the static rules.
  ASSERT_TRUE(broad_phase.SetKind(static_a, ProxyKind::kSleeping).ok());
  broad_phase.Update();
  EXPECT_EQ(broad_phase.Pairs(), expected);

  // Removing a proxy drops its pairs at once.
  ASSERT_TRUE(broad_phase.RemoveProxy(sleeping_b).ok());
  EXPECT_EQ(broad_phase.PairCount(), 0u);
  broad_phase.Update();
  EXPECT_EQ(broad_phase.PairCount(), 0u);
}

TEST(SortAndSweepBroadPhaseTest, IdsChosenOrHandedOut) {
  SortAndSweepBroadPhase broad_phase;
  ASSERT_TRUE(broad_phase.AddProxyWithId(3, UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kDynamic).ok());
  EXPECT_EQ(broad_phase.AddProxy(UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kDynamic).value(), 0);
  EXPECT_EQ(broad_phase.AddProxy(UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kDynamic).value(), 1);
  EXPECT_EQ(broad_phase.AddProxy(UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kDynamic).value(), 2);
  EXPECT_EQ(broad_phase.AddProxy(UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kDynamic).value(), 4);
  broad_phase.Update();
  EXPECT_EQ(broad_phase.PairCount(), 10u);  // 5 coincident dynamic boxes: 5 * 4 / 2
  ASSERT_TRUE(broad_phase.RemoveProxy(1).ok());
  EXPECT_EQ(broad_phase.PairCount(), 6u);
  EXPECT_EQ(broad_phase.AddProxy(UnitCubeAt(Vec3(5, 5, 5)), ProxyKind::kDynamic).value(), 1);
  broad_phase.Update();
  EXPECT_EQ(broad_phase.PairCount(), 6u);
  EXPECT_EQ(broad_phase.ProxyCount(), 5u);
}

// The world gives each body's proxy the body's slot as its id, and a
// removed body's slot is reused: 10,000 removals and re-additions of three
// ids keep at most three entries in the free list (each removal used to add
// one, 4 bytes a deleted body for the node's lifetime), and AddProxy still
// hands out the lowest id not in use.
TEST(SortAndSweepBroadPhaseTest, ReusedIdsDoNotGrowTheFreeList) {
  SortAndSweepBroadPhase broad_phase;
  for (int id = 0; id < 3; ++id) {
    ASSERT_TRUE(
        broad_phase.AddProxyWithId(id, UnitCubeAt(Vec3(2.0 * id, 0, 0)), ProxyKind::kDynamic).ok());
  }
  for (int round = 0; round < 10000; ++round) {
    const int id = round % 3;
    ASSERT_TRUE(broad_phase.RemoveProxy(id).ok());
    broad_phase.Update();
    ASSERT_TRUE(
        broad_phase.AddProxyWithId(id, UnitCubeAt(Vec3(2.0 * id, 0, 0)), ProxyKind::kDynamic).ok());
    broad_phase.Update();
  }
  EXPECT_LE(broad_phase.FreeIdCount(), 3u);
  ASSERT_TRUE(broad_phase.RemoveProxy(1).ok());
  EXPECT_EQ(broad_phase.AddProxy(UnitCubeAt(Vec3(9, 9, 9)), ProxyKind::kDynamic).value(), 1);
  EXPECT_EQ(broad_phase.AddProxy(UnitCubeAt(Vec3(9, 9, 9)), ProxyKind::kDynamic).value(), 3);
  EXPECT_EQ(broad_phase.ProxyCount(), 4u);
}

TEST(SortAndSweepBroadPhaseTest, RefusesBadInputAndKeepsState) {
  SortAndSweepBroadPhase broad_phase;
  const int id = broad_phase.AddProxy(UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kDynamic).value();
  const double nan = std::numeric_limits<double>::quiet_NaN();

  const Result<int> non_finite = broad_phase.AddProxy(Box(0, nan, 0, 1, 1, 1), ProxyKind::kDynamic);
  ASSERT_FALSE(non_finite.ok());
  EXPECT_NE(non_finite.message().find("non-finite"), std::string::npos);
  const Result<int> inverted = broad_phase.AddProxy(Box(0, 0, 2, 1, 1, 1), ProxyKind::kDynamic);
  ASSERT_FALSE(inverted.ok());
  EXPECT_NE(inverted.message().find("min > max on axis z"), std::string::npos);
  EXPECT_EQ(broad_phase.ProxyCount(), 1u);

  const Status duplicate =
      broad_phase.AddProxyWithId(id, UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kDynamic);
  EXPECT_NE(duplicate.message().find("already in use"), std::string::npos);
  EXPECT_FALSE(broad_phase.AddProxyWithId(-1, UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kDynamic).ok());
  EXPECT_FALSE(broad_phase
                   .AddProxyWithId(SortAndSweepBroadPhase::kMaxProxyId + 1,
                                   UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kDynamic)
                   .ok());

  const Status bad_move = broad_phase.SetAabb(id, Box(nan, 0, 0, 1, 1, 1));
  EXPECT_FALSE(bad_move.ok());
  EXPECT_EQ(broad_phase.GetAabb(id).min, Vec3(0, 0, 0));
  EXPECT_EQ(broad_phase.GetAabb(id).max, Vec3(1, 1, 1));
  const Status unknown = broad_phase.RemoveProxy(id + 1);
  EXPECT_NE(unknown.message().find("no proxy with id 1"), std::string::npos);
  EXPECT_FALSE(broad_phase.SetKind(42, ProxyKind::kStatic).ok());
  EXPECT_EQ(broad_phase.ProxyCount(), 1u);

  // The surviving proxy still pairs correctly.
  const int other =
      broad_phase.AddProxy(UnitCubeAt(Vec3(0.5, 0.5, 0.5)), ProxyKind::kStatic).value();
  broad_phase.Update();
  EXPECT_TRUE(broad_phase.HasPair(id, other));
  EXPECT_EQ(broad_phase.PairCount(), 1u);
}

TEST(BruteForcePairsTest, AppliesTheSameRules) {
  const std::vector<ProxyState> proxies = {
      {10, UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kStatic},
      {4, UnitCubeAt(Vec3(0.5, 0, 0)), ProxyKind::kStatic},
      {7, UnitCubeAt(Vec3(1, 1, 1)), ProxyKind::kDynamic},        // touches both at a corner/edge
      {2, UnitCubeAt(Vec3(0.5, 0.5, 2.5)), ProxyKind::kDynamic},  // overlaps only on x and y
  };
  const std::vector<ProxyPair> expected = {{4, 7}, {7, 10}};
  EXPECT_EQ(BruteForcePairs(proxies), expected);
}

// Proxies of one collision group never pair, whatever their kinds; group 0
// is none, and pairs as before.
TEST(SortAndSweepBroadPhaseTest, OneCollisionGroupNeverPairs) {
  SortAndSweepBroadPhase broad_phase;
  const int a = broad_phase.AddProxy(UnitCubeAt(Vec3(0, 0, 0)), ProxyKind::kDynamic, 3).value();
  const int b = broad_phase.AddProxy(UnitCubeAt(Vec3(0.5, 0, 0)), ProxyKind::kDynamic, 3).value();
  const int c = broad_phase.AddProxy(UnitCubeAt(Vec3(0, 0.5, 0)), ProxyKind::kDynamic, 4).value();
  const int d = broad_phase.AddProxy(UnitCubeAt(Vec3(0, 0, 0.5)), ProxyKind::kSleeping, 3).value();
  const int e = broad_phase.AddProxy(UnitCubeAt(Vec3(0.5, 0.5, 0)), ProxyKind::kDynamic).value();
  broad_phase.Update();
  EXPECT_FALSE(broad_phase.HasPair(a, b));
  EXPECT_FALSE(broad_phase.HasPair(a, d));
  EXPECT_TRUE(broad_phase.HasPair(a, c));
  EXPECT_TRUE(broad_phase.HasPair(b, e));
  EXPECT_TRUE(broad_phase.HasPair(c, d));
  // Waking d keeps it out of its group's pairs (SetKind's own path).
  ASSERT_TRUE(broad_phase.SetKind(d, ProxyKind::kDynamic).ok());
  broad_phase.Update();
  EXPECT_FALSE(broad_phase.HasPair(a, d));
  EXPECT_FALSE(broad_phase.HasPair(b, d));
  // Moving b across a (the insertion sort's path) pairs them no more.
  ASSERT_TRUE(broad_phase.SetAabb(b, UnitCubeAt(Vec3(-0.5, 0, 0))).ok());
  broad_phase.Update();
  EXPECT_FALSE(broad_phase.HasPair(a, b));
  const std::vector<ProxyState> states = {{a, broad_phase.GetAabb(a), ProxyKind::kDynamic, 3},
                                          {b, broad_phase.GetAabb(b), ProxyKind::kDynamic, 3},
                                          {c, broad_phase.GetAabb(c), ProxyKind::kDynamic, 4},
                                          {d, broad_phase.GetAabb(d), ProxyKind::kDynamic, 3},
                                          {e, broad_phase.GetAabb(e), ProxyKind::kDynamic, 0}};
  EXPECT_EQ(BruteForcePairs(states), broad_phase.Pairs());
}

// A random world of boxes: moving, bouncing inside a region, teleporting,
// added, removed, static, falling asleep and waking up. Half of the boxes
// live on a 1/16 m grid so that equal endpoint values (touching faces) are
// frequent.
class RandomBoxWorld {
 public:
  static constexpr double kRegion = 12.0;      // m, side of the cube the boxes bounce in
  static constexpr double kDt = 1.0 / 60.0;    // s
  static constexpr double kGrid = 1.0 / 16.0;  // m

  explicit RandomBoxWorld(std::uint64_t seed) : rng_(seed) {}

  void AddRandomBox(SortAndSweepBroadPhase& broad_phase, bool choose_id) {
    Box box;
    box.on_grid = Uniform(0, 1) < 0.5;
    for (int axis = 0; axis < 3; ++axis) {
      box.size[axis] = Uniform(0.05, 1.2);
      box.position[axis] = Uniform(0.0, kRegion - box.size[axis]);
    }
    const double kind_draw = Uniform(0, 1);
    box.kind = kind_draw < 0.1 ? ProxyKind::kStatic
                               : (kind_draw < 0.2 ? ProxyKind::kSleeping : ProxyKind::kDynamic);
    // A third in one of four collision groups (an articulation's links).
    box.group = Uniform(0, 1) < 0.33 ? 1 + static_cast<std::uint32_t>(Uniform(0, 4)) : 0;
    const bool fast = Uniform(0, 1) < 0.05;
    const double speed = fast ? 30.0 : 2.0;  // m/s
    for (int axis = 0; axis < 3; ++axis) {
      box.velocity[axis] = Uniform(-speed, speed);
    }
    Snap(box);
    int id = 0;
    if (choose_id) {
      // Mostly a fresh id above the current ones, sometimes a free low one.
      id = Uniform(0, 1) < 0.5 ? next_chosen_id_++ : static_cast<int>(Uniform(0, 2500));
      if (boxes_.count(id) != 0) {
        id = next_chosen_id_++;
      }
      ASSERT_TRUE(broad_phase.AddProxyWithId(id, BoxAabb(box), box.kind, box.group).ok());
    } else {
      const Result<int> added = broad_phase.AddProxy(BoxAabb(box), box.kind, box.group);
      ASSERT_TRUE(added.ok());
      id = added.value();
    }
    ASSERT_EQ(boxes_.count(id), 0u);
    boxes_[id] = box;
  }

  void RemoveRandomBox(SortAndSweepBroadPhase& broad_phase) {
    const int id = RandomId();
    ASSERT_TRUE(broad_phase.RemoveProxy(id).ok());
    boxes_.erase(id);
  }

  void ToggleRandomKind(SortAndSweepBroadPhase& broad_phase) {
    const int id = RandomId();
    Box& box = boxes_[id];
    const double draw = Uniform(0, 1);
    if (box.kind == ProxyKind::kDynamic) {
      box.kind = draw < 0.8 ? ProxyKind::kSleeping : ProxyKind::kStatic;
    } else if (box.kind == ProxyKind::kSleeping) {
      box.kind = draw < 0.8 ? ProxyKind::kDynamic : ProxyKind::kStatic;
    } else {
      box.kind = draw < 0.5 ? ProxyKind::kDynamic : ProxyKind::kSleeping;
    }
    ASSERT_TRUE(broad_phase.SetKind(id, box.kind).ok());
  }

  void Teleport(SortAndSweepBroadPhase& broad_phase) {
    const int id = RandomId();
    Box& box = boxes_[id];
    for (int axis = 0; axis < 3; ++axis) {
      box.position[axis] = Uniform(0.0, kRegion - box.size[axis]);
    }
    Snap(box);
    ASSERT_TRUE(broad_phase.SetAabb(id, BoxAabb(box)).ok());
  }

  // Moves the dynamic boxes by velocity * dt, reflecting at the region walls.
  void Move(SortAndSweepBroadPhase& broad_phase) {
    for (auto& [id, box] : boxes_) {
      if (box.kind != ProxyKind::kDynamic) {
        continue;
      }
      box.position += box.velocity * kDt;
      for (int axis = 0; axis < 3; ++axis) {
        if (box.position[axis] < 0.0) {
          box.position[axis] = -box.position[axis];
          box.velocity[axis] = -box.velocity[axis];
        }
        const double limit = kRegion - box.size[axis];
        if (box.position[axis] > limit) {
          box.position[axis] = 2.0 * limit - box.position[axis];
          box.velocity[axis] = -box.velocity[axis];
        }
      }
      Snap(box);
      ASSERT_TRUE(broad_phase.SetAabb(id, BoxAabb(box)).ok());
    }
  }

  std::vector<ProxyState> States() const {
    std::vector<ProxyState> states;
    states.reserve(boxes_.size());
    for (const auto& [id, box] : boxes_) {
      states.push_back(ProxyState{id, BoxAabb(box), box.kind, box.group});
    }
    return states;
  }

  std::size_t size() const { return boxes_.size(); }

 private:
  struct Box {
    Vec3 position = Vec3::Zero();  // m, min corner
    Vec3 size = Vec3::Ones();      // m
    Vec3 velocity = Vec3::Zero();  // m/s
    ProxyKind kind = ProxyKind::kDynamic;
    std::uint32_t group = 0;
    bool on_grid = false;
  };

  static Aabb BoxAabb(const Box& box) { return Aabb{box.position, box.position + box.size}; }

  void Snap(Box& box) const {
    if (!box.on_grid) {
      return;
    }
    for (int axis = 0; axis < 3; ++axis) {
      box.size[axis] = std::max(kGrid, std::round(box.size[axis] / kGrid) * kGrid);
      box.position[axis] =
          std::clamp(std::round(box.position[axis] / kGrid) * kGrid, 0.0, kRegion - box.size[axis]);
    }
  }

  double Uniform(double low, double high) {
    return std::uniform_real_distribution<double>(low, high)(rng_);
  }

  int RandomId() {
    // std::map has no random access; walk from a random lower bound.
    auto it = boxes_.lower_bound(static_cast<int>(Uniform(0, next_chosen_id_)));
    if (it == boxes_.end()) {
      it = boxes_.begin();
    }
    return it->first;
  }

  std::mt19937_64 rng_;
  std::map<int, Box> boxes_;
  int next_chosen_id_ = 3000;
};

TEST(SortAndSweepBroadPhaseTest, MatchesBruteForceOver500StepsOf2000Boxes) {
  constexpr int kBoxes = 2000;
  constexpr int kSteps = 500;
  SortAndSweepBroadPhase broad_phase;
  RandomBoxWorld world(20240611);
  for (int i = 0; i < kBoxes; ++i) {
    world.AddRandomBox(broad_phase, /*choose_id=*/i % 7 == 0);
  }
  std::mt19937_64 schedule_rng(7);
  auto count = [&schedule_rng](int max_count) {
    return std::uniform_int_distribution<int>(0, max_count)(schedule_rng);
  };
  std::size_t total_pairs = 0;
  for (int step = 0; step < kSteps; ++step) {
    if (step > 0) {
      world.Move(broad_phase);
      const bool batch = step % 100 == 50;  // more adds than the rebuild threshold
      const int removals = batch ? 60 : count(6);
      for (int i = 0; i < removals; ++i) {
        world.RemoveRandomBox(broad_phase);
      }
      const int additions = batch ? 60 : count(6);
      for (int i = 0; i < additions; ++i) {
        world.AddRandomBox(broad_phase, /*choose_id=*/i % 3 == 0);
      }
      const int toggles = count(12);
      for (int i = 0; i < toggles; ++i) {
        world.ToggleRandomKind(broad_phase);
      }
      const int teleports = count(3);
      for (int i = 0; i < teleports; ++i) {
        world.Teleport(broad_phase);
      }
    }
    if (HasFatalFailure()) {
      return;
    }
    broad_phase.Update();
    ASSERT_EQ(broad_phase.ProxyCount(), world.size());
    const std::vector<ProxyPair> expected = BruteForcePairs(world.States());
    const std::vector<ProxyPair> actual = broad_phase.Pairs();
    ASSERT_EQ(actual.size(), expected.size()) << "step " << step;
    ASSERT_TRUE(actual == expected)
        << "step " << step << ":" << DescribeDifference(actual, expected);
    total_pairs += actual.size();
  }
  // The scene must be crowded enough to exercise the pair updates: about one
  // pair per box (mean box 0.625 m on a side in a 12 m cube: 2000 boxes see
  // 2000 * 1999 / 2 * (1.25 / 12)^3 ~ 2260 overlapping pairs).
  EXPECT_GT(total_pairs / kSteps, 1000u);
}

// SortPairKeys is the broad phase's fast sort; std::sort is its reference.
// Distinct keys a << 32 | b with a < b, from ids below a bound that takes
// the counting sorts, and with one id far past it, which takes std::sort.
TEST(SortPairKeysTest, GivesStdSortsOrder) {
  std::mt19937_64 random(7);
  for (const std::uint32_t id_bound : {2u, 50u, 4000u, 4000000u}) {
    std::uniform_int_distribution<std::uint32_t> id(0, id_bound - 1);
    std::set<std::uint64_t> unique;
    for (int k = 0; k < 3000; ++k) {
      std::uint32_t a = id(random);
      std::uint32_t b = id(random);
      if (a == b) continue;
      if (b < a) std::swap(a, b);
      unique.insert((std::uint64_t{a} << 32) | b);
    }
    std::vector<std::uint64_t> keys(unique.begin(), unique.end());
    std::shuffle(keys.begin(), keys.end(), random);
    std::vector<std::uint64_t> expected = keys;
    std::sort(expected.begin(), expected.end());
    SortPairKeys(&keys);
    EXPECT_EQ(keys, expected) << "ids below " << id_bound;
  }
  std::vector<std::uint64_t> none;
  SortPairKeys(&none);
  EXPECT_TRUE(none.empty());
}

}  // namespace
}  // namespace rigid_body_sim::physics
