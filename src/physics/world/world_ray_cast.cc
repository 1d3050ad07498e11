// World::CastRays: each ray against every enabled body's shapes, through a
// four-wide tree of the shapes' world boxes built for the batch, on
// the task pool for large batches.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_set>
#include <utility>
#include <variant>

#include "physics/collision/ray_cast.h"
#include "physics/geometry/aabb.h"
#include "physics/geometry/shape_bounds.h"
#include "physics/geometry/wide_box_tree.h"
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {
namespace {

// Rays per task of the pool.
constexpr std::size_t kRaysPerChunk = 256;
// How many rays ahead in the cast order a ray and its hit are fetched.
constexpr std::size_t kAhead = 16;
constexpr double kUnitTolerance = 1e-9;

// One shape of the scene, posed in the world.
struct ShapeEntry {
  std::uint32_t body = 0;
  int shape = 0;
  ShapeFrame frame;  // the shape's pose in the world
  Aabb box;
};

// Shapes per leaf of the batch's tree: a shape costs more to test than a
// box, so leaves are small.
constexpr int kLeafShapes = 1;

// The batch's shapes in the order of their tree.
struct ShapeTree {
  std::vector<ShapeEntry> entries;
  WideBoxTree tree;

  void Build() {
    std::vector<Aabb> boxes(entries.size());
    for (std::size_t i = 0; i < entries.size(); ++i) boxes[i] = entries[i].box;
    std::vector<int> order;
    tree = WideBoxTree::Build(boxes, kLeafShapes, &order);
    std::vector<ShapeEntry> sorted(entries.size());
    for (std::size_t i = 0; i < sorted.size(); ++i) sorted[i] = entries[order[i]];
    entries.swap(sorted);
  }
};

// The message is built only for a bad ray: a batch of 100,000 good rays
// spent 10 % of its time formatting names it never showed.
Status ValidateRay(const Ray& ray, std::size_t index) {
  const bool origin_ok = IsFinite(ray.origin);
  const bool direction_ok =
      IsFinite(ray.direction) && std::abs(ray.direction.norm() - 1.0) <= kUnitTolerance;
  const bool distance_ok = ray.max_distance >= 0.0;
  if (origin_ok && direction_ok && distance_ok) return Status::Ok();
  const std::string name = "ray " + std::to_string(index) + ": ";
  if (!origin_ok) return Status::Error(name + "origin is not finite");
  if (!direction_ok) {
    return Status::Error(name + "direction must be a finite unit vector, has length " +
                         FormatNumber(ray.direction.norm()));
  }
  return Status::Error(name + "max_distance " + FormatNumber(ray.max_distance) + " must be >= 0");
}

void Consider(const ShapeEntry& entry, const ShapeGeometry& geometry, const Ray& ray,
              const std::vector<Body>& bodies, RayHit* best) {
  Ray shortened = ray;
  shortened.max_distance = std::min(ray.max_distance, best->distance);
  RayHit hit = RayCastShape(geometry, entry.frame, shortened);
  if (!hit.hit || (best->hit && hit.distance >= best->distance)) return;
  hit.body = BodyId{entry.body, bodies[entry.body].generation};
  hit.shape = entry.shape;
  *best = hit;
}

// The shapes cast on their own (half-spaces, and shapes as large as the
// scene), then the tree walked nearest child first, a leaf skipped when it
// begins beyond the nearest hit so far.
RayHit CastOneRay(const Ray& ray, const ShapeTree& tree, const std::vector<ShapeEntry>& apart,
                  const std::vector<Body>& bodies) {
  RayHit best;
  const auto consider = [&](const ShapeEntry& entry) {
    Consider(entry, bodies[entry.body].shapes[entry.shape].geometry, ray, bodies, &best);
  };
  for (const ShapeEntry& entry : apart) consider(entry);
  double reach = best.hit ? best.distance : ray.max_distance;
  tree.tree.CastRay(ray.origin, ray.direction, &reach, [&](int first, int count) {
    for (int i = first; i < first + count; ++i) consider(tree.entries[i]);
    if (best.hit) reach = best.distance;
  });
  return best;
}

// Shapes whose box spans more than a quarter of the scene's (a terrain
// under everything else) are cast on their own, before the tree: in the
// tree their box would widen every node above them, and each ray would
// open most of the tree on its way down to them (100,000 rays over 1,000
// boxes on a 99k-triangle terrain, one thread: 205 ms with the terrain in
// the tree, 185 ms with it apart).
// Returns the box of all the entries (zero when there are none).
Aabb MoveLargeShapesApart(std::vector<ShapeEntry>* entries, std::vector<ShapeEntry>* apart) {
  if (entries->empty()) return Aabb{};
  Aabb scene = entries->front().box;
  for (const ShapeEntry& entry : *entries) scene = scene.Union(entry.box);
  if (entries->size() < 2) return scene;
  const double limit = 0.25 * (scene.max - scene.min).norm();
  const auto large = [limit](const ShapeEntry& entry) {
    return (entry.box.max - entry.box.min).norm() > limit;
  };
  for (const ShapeEntry& entry : *entries) {
    if (large(entry)) apart->push_back(entry);
  }
  entries->erase(std::remove_if(entries->begin(), entries->end(), large), entries->end());
  return scene;
}

// Spreads the low 10 bits of v to every third bit.
std::uint32_t SpreadBits(std::uint32_t v) {
  v &= 0x3ff;
  v = (v | v << 16) & 0x030000ffu;
  v = (v | v << 8) & 0x0300f00fu;
  v = (v | v << 4) & 0x030c30c3u;
  v = (v | v << 2) & 0x09249249u;
  return v;
}

// The middle of the ray's stretch inside `box` (Kay and Kajiya 1986,
// "Ray tracing complex scenes", the slab test), or its origin if it misses
// the box: where the ray meets most of what it can hit.
Vec3 MiddleInBox(const Ray& ray, const Aabb& box) {
  double enter = 0.0;
  double leave = ray.max_distance;
  for (int axis = 0; axis < 3; ++axis) {
    const double inverse = 1.0 / ray.direction[axis];
    const double t1 = (box.min[axis] - ray.origin[axis]) * inverse;
    const double t2 = (box.max[axis] - ray.origin[axis]) * inverse;
    // A NaN (0 times an infinite inverse: a ray in a slab's plane) never
    // replaces enter or leave, as std::max and std::min return their first
    // argument when a comparison fails.
    enter = std::max(enter, std::min(t1, t2));
    leave = std::min(leave, std::max(t1, t2));
  }
  if (!(enter <= leave)) return ray.origin;
  return ray.origin + (0.5 * (enter + leave)) * ray.direction;
}

// The rays in the Morton order of the middles of their stretches within
// `box`, the scene's (Morton 1966, "A computer oriented geodetic data
// base"), 1,024 cells per axis: rays that pass near each other walk the
// same tree nodes and triangles, which then stay in cache (ray_bench's
// 100,000 rays, the terrain's walk alone: 46 ms in the given order, 34 ms
// in the order of the origins, 32 ms in this one). The 30-bit keys are
// sorted by a least-significant-digit radix sort, three stable passes of
// 10 bits (Knuth 1998, The Art of Computer Programming, vol. 3, section
// 5.2.5), 8x faster here than a comparison sort. Each ray's answer does
// not depend on the order.
std::vector<std::uint32_t> CastOrder(const std::vector<Ray>& rays, const Aabb& box) {
  constexpr int kDigitBits = 10;
  constexpr std::uint32_t kDigits = 1u << kDigitBits;
  const Vec3 extent = (box.max - box.min).cwiseMax(Vec3::Constant(1e-9));
  // Each entry is its key above its ray's index, so that the passes read
  // their input in order instead of gathering keys by index.
  std::vector<std::uint64_t> entries(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Vec3 unit =
        ((MiddleInBox(rays[i], box) - box.min).cwiseQuotient(extent)).cwiseMax(0.0).cwiseMin(1.0);
    std::uint64_t key = 0;
    for (int axis = 0; axis < 3; ++axis) {
      key |= SpreadBits(static_cast<std::uint32_t>(unit[axis] * (kDigits - 1))) << axis;
    }
    entries[i] = key << 32 | i;
  }
  std::vector<std::uint64_t> next(rays.size());
  for (int pass = 0; pass < 3; ++pass) {
    const int shift = 32 + pass * kDigitBits;
    std::vector<std::uint32_t> start(kDigits + 1, 0);
    for (const std::uint64_t entry : entries) ++start[((entry >> shift) & (kDigits - 1)) + 1];
    for (std::uint32_t d = 0; d < kDigits; ++d) start[d + 1] += start[d];
    for (const std::uint64_t entry : entries) {
      next[start[(entry >> shift) & (kDigits - 1)]++] = entry;
    }
    entries.swap(next);
  }
  std::vector<std::uint32_t> order(rays.size());
  for (std::size_t k = 0; k < rays.size(); ++k) {
    order[k] = static_cast<std::uint32_t>(entries[k] & 0xffffffffu);
  }
  return order;
}

}  // namespace

Result<std::vector<RayHit>> WorldImpl::CastRays(const std::vector<Ray>& rays,
                                                const std::vector<BodyId>& ignore) const {
  if (rays.size() > kMaxRaysPerCast) {
    return Status::Error("rays: " + std::to_string(rays.size()) + " rays, at most " +
                         std::to_string(kMaxRaysPerCast));
  }
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (Status status = ValidateRay(rays[i], i); !status.ok()) return status;
  }
  std::unordered_set<std::uint32_t> ignored;
  for (const BodyId id : ignore) {
    if (IsValid(id)) ignored.insert(id.index);
  }
  ShapeTree tree;
  std::vector<ShapeEntry> apart;
  for (std::uint32_t b = 0; b < bodies_.size(); ++b) {
    const Body& body = bodies_[b];
    if (!body.in_use || body.disabled || ignored.count(b) > 0) continue;
    const Pose world_from_body = body.WorldFromBody();
    for (std::size_t s = 0; s < body.shapes.size(); ++s) {
      const ShapeGeometry& geometry = body.shapes[s].geometry;
      // A static mesh's extra contact slots are copies of its first.
      if (const auto* mesh = std::get_if<StaticMesh>(&geometry); mesh && mesh->slot != 0) continue;
      const Pose world_from_shape = world_from_body * body.shapes[s].body_from_shape;
      ShapeEntry entry{b, static_cast<int>(s), ShapeFrame(world_from_shape), Aabb{}};
      if (std::holds_alternative<HalfSpace>(geometry)) {
        apart.push_back(entry);
        continue;
      }
      entry.box = ShapeAabb(geometry, world_from_shape);
      tree.entries.push_back(entry);
    }
  }
  // The large shapes' boxes count: a terrain holds most of the hits.
  const Aabb scene = MoveLargeShapesApart(&tree.entries, &apart);
  tree.Build();
  const std::vector<std::uint32_t> order = CastOrder(rays, scene);
  // Each ray is read and its hit written in place, in the cast order, and
  // the ray and the hit kAhead places on are asked for meanwhile: a ray and
  // its 80-byte hit each missed the cache in the middle of the walk (half
  // of a batch's time, when nothing asked for them ahead). Copies of the
  // batch in the cast order, the way before, were as fast when their pages
  // stayed with the process, but took 14 MB of fresh pages per 100,000 rays
  // when the allocator gave them back: a batch on an empty world took 26 ms
  // then, 5 ms now, most of the difference page faults.
  std::vector<RayHit> hits(rays.size());
  pool_->ParallelFor(rays.size(), kRaysPerChunk, [&](std::size_t k) {
    if (k + kAhead < rays.size()) {
      __builtin_prefetch(&rays[order[k + kAhead]]);
      __builtin_prefetch(&hits[order[k + kAhead]], 1);
    }
    hits[order[k]] = CastOneRay(rays[order[k]], tree, apart, bodies_);
  });
  return hits;
}

}  // namespace rigid_body_sim::physics
