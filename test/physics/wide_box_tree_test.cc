// WideBoxTree against testing every box in double precision: the
// single-precision walk may visit more, never less. Boxes far from the
// origin, thin and flat boxes, rays along faces and axis-parallel rays are
// where rounding to float could lose a box.
#include "physics/geometry/wide_box_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

namespace rigid_body_sim::physics {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The ray's interval in the closed box (Kay and Kajiya 1986, slabs), in
// double precision; an axis the ray does not move along keeps it whole or
// empties it. Returns the entry, or +inf when it misses within reach.
double SlabEntry(const Aabb& box, const Vec3& origin, const Vec3& direction, double reach) {
  double entry = 0.0;
  double exit = reach;
  for (int axis = 0; axis < 3; ++axis) {
    if (direction[axis] == 0.0) {
      if (origin[axis] < box.min[axis] || origin[axis] > box.max[axis]) return kInfinity;
      continue;
    }
    const double t1 = (box.min[axis] - origin[axis]) / direction[axis];
    const double t2 = (box.max[axis] - origin[axis]) / direction[axis];
    entry = std::max(entry, std::min(t1, t2));
    exit = std::min(exit, std::max(t1, t2));
  }
  return entry <= exit ? entry : kInfinity;
}

struct Scene {
  std::vector<Aabb> boxes;
  WideBoxTree tree;
  std::vector<int> order;
};

// `count` boxes around `centre`, of sizes from 1e-6 m to 1 m, some flat.
Scene MakeScene(int count, const Vec3& centre, int leaf_size, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> place(-20.0, 20.0);
  std::uniform_real_distribution<double> exponent(-6.0, 0.0);
  Scene scene;
  for (int i = 0; i < count; ++i) {
    const Vec3 middle = centre + Vec3(place(random), place(random), place(random));
    Vec3 half(std::pow(10.0, exponent(random)), std::pow(10.0, exponent(random)),
              std::pow(10.0, exponent(random)));
    if (i % 5 == 0) half.z() = 0.0;  // a flat box, as a horizontal triangle's
    scene.boxes.push_back(Aabb{middle - half, middle + half});
  }
  scene.tree = WideBoxTree::Build(scene.boxes, leaf_size, &scene.order);
  return scene;
}

// The items of every leaf the walk calls, with the reach left unchanged.
std::set<int> Visited(const Scene& scene, const Vec3& origin, const Vec3& direction, double reach) {
  std::set<int> items;
  scene.tree.CastRay(origin, direction, &reach, [&](int first, int count) {
    for (int i = first; i < first + count; ++i) items.insert(scene.order[i]);
  });
  return items;
}

TEST(WideBoxTreeTest, EveryItemIsInExactlyOneLeaf) {
  const Scene scene = MakeScene(1000, Vec3::Zero(), 3, 1);
  std::vector<int> sorted = scene.order;
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(sorted[i], i);
  // A box query as large as the scene calls each item's leaf once.
  std::vector<int> seen;
  scene.tree.QueryBox(scene.tree.bounds(), [&](int first, int count) {
    for (int i = first; i < first + count; ++i) seen.push_back(scene.order[i]);
  });
  std::sort(seen.begin(), seen.end());
  EXPECT_EQ(seen, sorted);
}

TEST(WideBoxTreeTest, RayWalkVisitsEveryBoxTheExactRayMeets) {
  // Near the origin and 1e4 m away, where a float's step is 1 mm.
  for (const Vec3& centre : {Vec3(0.0, 0.0, 0.0), Vec3(1e4, -3e3, 7e3)}) {
    for (const int leaf_size : {1, 4}) {
      const Scene scene = MakeScene(2000, centre, leaf_size, 7);
      std::mt19937 random(11);
      std::uniform_real_distribution<double> place(-25.0, 25.0);
      std::uniform_int_distribution<int> pick(0, 1999);
      int checked = 0;
      for (int k = 0; k < 3000; ++k) {
        const Vec3 origin = centre + Vec3(place(random), place(random), place(random));
        Vec3 direction;
        if (k % 3 == 0) {
          // At a random point of a random box: the ray must find that box.
          const Aabb& box = scene.boxes[pick(random)];
          direction = box.min + 0.5 * (box.max - box.min) - origin;
        } else {
          direction = Vec3(place(random), place(random), place(random));
        }
        if (k % 7 == 0) direction.y() = 0.0;  // parallel to the y slabs
        if (direction.norm() == 0.0) continue;
        direction.normalize();
        const std::set<int> visited = Visited(scene, origin, direction, 100.0);
        for (int i = 0; i < 2000; ++i) {
          if (SlabEntry(scene.boxes[i], origin, direction, 100.0) == kInfinity) continue;
          ++checked;
          EXPECT_EQ(visited.count(i), 1u) << "box " << i << " missed by ray " << k;
        }
      }
      EXPECT_GT(checked, 800);  // not vacuous: most aimed rays reach their box
    }
  }
}

TEST(WideBoxTreeTest, RayAlongAFaceVisitsTheBox) {
  // Rays that only graze: in a box's top face, along its edge, from its
  // corner, and ending exactly on its near face.
  const std::vector<Aabb> boxes{Aabb{Vec3(1.0, 1.0, 1.0), Vec3(2.0, 2.0, 1.0)},
                                Aabb{Vec3(4.1, -0.3, 0.7), Vec3(4.6, 0.3, 0.9)}};
  std::vector<int> order;
  const WideBoxTree tree = WideBoxTree::Build(boxes, 1, &order);
  const auto visits = [&](const Vec3& origin, const Vec3& direction, double reach, int item) {
    bool found = false;
    tree.CastRay(origin, direction.normalized(), &reach, [&](int first, int count) {
      for (int i = first; i < first + count; ++i) found = found || order[i] == item;
    });
    return found;
  };
  EXPECT_TRUE(visits(Vec3(0.0, 1.5, 1.0), Vec3::UnitX(), 10.0, 0));
  EXPECT_TRUE(visits(Vec3(0.0, 1.0, 1.0), Vec3::UnitX(), 10.0, 0));
  EXPECT_TRUE(visits(Vec3(2.0, 2.0, 1.0), Vec3(1.0, 1.0, 0.0), 10.0, 0));
  EXPECT_TRUE(visits(Vec3(4.0, 0.0, 0.8), Vec3::UnitX(), 0.1, 1));
  EXPECT_FALSE(visits(Vec3(4.0, 0.0, 0.8), -Vec3::UnitX(), 10.0, 1));
}

TEST(WideBoxTreeTest, ShortenedReachFindsTheNearestEntryOfBruteForce) {
  const Scene scene = MakeScene(3000, Vec3(5.0, 5.0, 5.0), 4, 3);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> place(-30.0, 30.0);
  for (int k = 0; k < 2000; ++k) {
    const Vec3 origin(place(random), place(random), place(random));
    const Vec3 direction = Vec3(place(random), place(random), place(random)).normalized();
    double expected = kInfinity;
    for (const Aabb& box : scene.boxes) {
      expected = std::min(expected, SlabEntry(box, origin, direction, 80.0));
    }
    double reach = 80.0;
    double found = kInfinity;
    scene.tree.CastRay(origin, direction, &reach, [&](int first, int count) {
      for (int i = first; i < first + count; ++i) {
        const double t = SlabEntry(scene.boxes[scene.order[i]], origin, direction, reach);
        if (t < found) found = reach = t;
      }
    });
    EXPECT_EQ(found, expected) << "ray " << k;
  }
}

TEST(WideBoxTreeTest, BoxQueryVisitsEveryOverlappingBox) {
  const Scene scene = MakeScene(2000, Vec3(-3e3, 0.0, 2e3), 4, 9);
  std::mt19937 random(13);
  std::uniform_real_distribution<double> place(-22.0, 22.0);
  std::uniform_real_distribution<double> size(0.0, 3.0);
  for (int k = 0; k < 500; ++k) {
    const Vec3 corner = Vec3(-3e3, 0.0, 2e3) + Vec3(place(random), place(random), place(random));
    const Aabb query{corner, corner + Vec3(size(random), size(random), size(random))};
    std::set<int> visited;
    scene.tree.QueryBox(query, [&](int first, int count) {
      for (int i = first; i < first + count; ++i) visited.insert(scene.order[i]);
    });
    for (int i = 0; i < 2000; ++i) {
      if (!scene.boxes[i].Overlaps(query)) continue;
      EXPECT_EQ(visited.count(i), 1u) << "box " << i;
    }
  }
}

TEST(WideBoxTreeTest, EmptyTreeVisitsNothing) {
  std::vector<int> order;
  const WideBoxTree tree = WideBoxTree::Build({}, 4, &order);
  double reach = 10.0;
  int calls = 0;
  tree.CastRay(Vec3::Zero(), Vec3::UnitX(), &reach, [&](int, int) { ++calls; });
  tree.QueryBox(Aabb{Vec3::Constant(-1.0), Vec3::Constant(1.0)}, [&](int, int) { ++calls; });
  EXPECT_EQ(calls, 0);
  EXPECT_TRUE(order.empty());
}

}  // namespace
}  // namespace rigid_body_sim::physics
