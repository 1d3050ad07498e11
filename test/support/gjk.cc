#include "support/gjk.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <initializer_list>
#include <limits>

namespace rigid_body_sim::physics {
namespace {

// Stop when |v|^2 - v.w <= kRelativeTolerance |v|^2: the lower bound v.w/|v|
// on the distance is then within ~kRelativeTolerance/2 of the upper bound |v|.
constexpr double kRelativeTolerance = 1e-14;
// For small |v| the gap |v| - v.w/|v| cannot shrink below rounding of v.w,
// about eps |w|, so also stop when the gap is below kAbsoluteTolerance |w|.
constexpr double kAbsoluteTolerance = 1e-13;
// A tetrahedron with |det| below kFlatTolerance times its longest edge cubed
// is flat (support points on a planar face of A - B): it has no inside, and
// the closest point is on one of its triangles.
constexpr double kFlatTolerance = 1e-10;
// |v| below kOverlapTolerance times the largest simplex point is zero within
// rounding: the origin is on or inside the Minkowski difference.
constexpr double kOverlapTolerance = 1e-12;
constexpr int kMaxIterations = 128;

struct SimplexVertex {
  Vec3 w;  // a - b, world
  Vec3 a;  // support point of A, world
  Vec3 b;  // support point of B, world
};

struct Simplex {
  SimplexVertex vertices[4];
  double weights[4] = {0.0, 0.0, 0.0, 0.0};  // barycentric coordinates of v
  int count = 0;
};

// Keeps the listed vertices with their barycentric weights.
void Keep(Simplex* simplex, std::initializer_list<int> indices,
          std::initializer_list<double> weights) {
  SimplexVertex kept[4];
  int n = 0;
  for (int i : indices) kept[n++] = simplex->vertices[i];
  n = 0;
  for (double weight : weights) simplex->weights[n++] = weight;
  for (int i = 0; i < n; ++i) simplex->vertices[i] = kept[i];
  simplex->count = n;
}

// Closest point of segment (i, j) to the origin: v = w_i + t (w_j - w_i)
// with t = -w_i.(w_j - w_i) / |w_j - w_i|^2 clamped to [0, 1]; the clamp
// chooses the Voronoi region (vertex i, vertex j or the edge).
void SolveSegment(Simplex* simplex, int i, int j) {
  const Vec3& p = simplex->vertices[i].w;
  const Vec3 edge = simplex->vertices[j].w - p;
  const double length_squared = edge.squaredNorm();
  const double t = length_squared > 0.0 ? -p.dot(edge) / length_squared : 0.0;
  if (t <= 0.0) {
    Keep(simplex, {i}, {1.0});
  } else if (t >= 1.0) {
    Keep(simplex, {j}, {1.0});
  } else {
    Keep(simplex, {i, j}, {1.0 - t, t});
  }
}

double SegmentDistanceSquared(const Simplex& simplex, int i, int j) {
  Simplex copy = simplex;
  SolveSegment(&copy, i, j);
  Vec3 v = Vec3::Zero();
  for (int k = 0; k < copy.count; ++k) v += copy.weights[k] * copy.vertices[k].w;
  return v.squaredNorm();
}

// Closest point of triangle (i, j, k) to the origin by its Voronoi regions
// (Ericson, Real-Time Collision Detection 2005, section 5.1.5): the
// dot products d1..d6 of the edges with the vertex-to-origin vectors decide
// the vertex regions, the signed areas va, vb, vc the edge regions, and
// otherwise v is inside with barycentric coordinates (va, vb, vc) / sum.
void SolveTriangle(Simplex* simplex, int i, int j, int k) {
  const Vec3& a = simplex->vertices[i].w;
  const Vec3& b = simplex->vertices[j].w;
  const Vec3& c = simplex->vertices[k].w;
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const double d1 = -ab.dot(a);
  const double d2 = -ac.dot(a);
  if (d1 <= 0.0 && d2 <= 0.0) return Keep(simplex, {i}, {1.0});
  const double d3 = -ab.dot(b);
  const double d4 = -ac.dot(b);
  if (d3 >= 0.0 && d4 <= d3) return Keep(simplex, {j}, {1.0});
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double t = d1 / (d1 - d3);
    return Keep(simplex, {i, j}, {1.0 - t, t});
  }
  const double d5 = -ab.dot(c);
  const double d6 = -ac.dot(c);
  if (d6 >= 0.0 && d5 <= d6) return Keep(simplex, {k}, {1.0});
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double t = d2 / (d2 - d6);
    return Keep(simplex, {i, k}, {1.0 - t, t});
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return Keep(simplex, {j, k}, {1.0 - t, t});
  }
  const double sum = va + vb + vc;
  if (!(sum > 0.0)) {
    // Degenerate (collinear) triangle: the closest point is on an edge.
    const double dij = SegmentDistanceSquared(*simplex, i, j);
    const double dik = SegmentDistanceSquared(*simplex, i, k);
    const double djk = SegmentDistanceSquared(*simplex, j, k);
    if (dij <= dik && dij <= djk) return SolveSegment(simplex, i, j);
    if (dik <= djk) return SolveSegment(simplex, i, k);
    return SolveSegment(simplex, j, k);
  }
  Keep(simplex, {i, j, k}, {va / sum, vb / sum, vc / sum});
}

double TriangleDistanceSquared(const Simplex& simplex, int i, int j, int k, Simplex* solved) {
  *solved = simplex;
  SolveTriangle(solved, i, j, k);
  Vec3 v = Vec3::Zero();
  for (int m = 0; m < solved->count; ++m) v += solved->weights[m] * solved->vertices[m].w;
  return v.squaredNorm();
}

// Tetrahedron: the origin is inside when it lies on the same side of every
// face as the opposite vertex. Otherwise the closest point is on one of the
// faces the origin sees; a flat tetrahedron has all faces checked.
// Returns false when the origin is inside.
bool SolveTetrahedron(Simplex* simplex) {
  static constexpr int kFaces[4][4] = {{0, 1, 2, 3}, {0, 3, 1, 2}, {0, 2, 3, 1}, {1, 3, 2, 0}};
  const Vec3& w0 = simplex->vertices[0].w;
  double longest_squared = 0.0;
  for (int i = 1; i < 4; ++i) {
    longest_squared = std::max(longest_squared, (simplex->vertices[i].w - w0).squaredNorm());
  }
  const double determinant = (simplex->vertices[1].w - w0)
                                 .cross(simplex->vertices[2].w - w0)
                                 .dot(simplex->vertices[3].w - w0);
  const bool flat =
      std::abs(determinant) <= kFlatTolerance * longest_squared * std::sqrt(longest_squared);
  double best = std::numeric_limits<double>::infinity();
  Simplex best_simplex;
  bool any_outside = false;
  for (const auto& face : kFaces) {
    const Vec3& a = simplex->vertices[face[0]].w;
    const Vec3 normal = (simplex->vertices[face[1]].w - a).cross(simplex->vertices[face[2]].w - a);
    const double origin_side = -normal.dot(a);
    const double opposite_side = normal.dot(simplex->vertices[face[3]].w - a);
    if (!flat && origin_side * opposite_side >= 0.0) continue;
    any_outside = true;
    Simplex solved;
    const double distance_squared =
        TriangleDistanceSquared(*simplex, face[0], face[1], face[2], &solved);
    if (distance_squared < best) {
      best = distance_squared;
      best_simplex = solved;
    }
  }
  if (!any_outside) return false;
  *simplex = best_simplex;
  return true;
}

int Support(const std::vector<Vec3>& points, const Vec3& direction) {
  int best = 0;
  double best_distance = points[0].dot(direction);
  for (int i = 1; i < static_cast<int>(points.size()); ++i) {
    const double distance = points[i].dot(direction);
    if (distance > best_distance) {
      best = i;
      best_distance = distance;
    }
  }
  return best;
}

std::vector<Vec3> ToWorld(const std::vector<Vec3>& points, const Pose& world_from_points) {
  std::vector<Vec3> world(points.size());
  for (std::size_t i = 0; i < world.size(); ++i) world[i] = world_from_points * points[i];
  return world;
}

// Keeps the sub-simplex whose Voronoi region holds the origin, with the
// barycentric weights of the origin's projection; false when a tetrahedron
// contains the origin.
bool ReduceSimplex(Simplex* simplex) {
  switch (simplex->count) {
    case 1:
      Keep(simplex, {0}, {1.0});
      return true;
    case 2:
      SolveSegment(simplex, 0, 1);
      return true;
    case 3:
      SolveTriangle(simplex, 0, 1, 2);
      return true;
    default:
      return SolveTetrahedron(simplex);
  }
}

// The closest points on A and B, and their distance, from the weights of
// the final simplex.
void SetClosestPoints(const Simplex& simplex, GjkResult* result) {
  result->point_a_world = Vec3::Zero();
  result->point_b_world = Vec3::Zero();
  for (int i = 0; i < simplex.count; ++i) {
    result->point_a_world += simplex.weights[i] * simplex.vertices[i].a;
    result->point_b_world += simplex.weights[i] * simplex.vertices[i].b;
  }
  Vec3 closest = Vec3::Zero();
  for (int i = 0; i < simplex.count; ++i) closest += simplex.weights[i] * simplex.vertices[i].w;
  result->distance = closest.norm();
  result->simplex_count = simplex.count;
}

}  // namespace

GjkResult GjkDistance(const GjkInput& input) {
  assert(input.points_a != nullptr && !input.points_a->empty());
  assert(input.points_b != nullptr && !input.points_b->empty());
  const std::vector<Vec3> a_world = ToWorld(*input.points_a, input.world_from_a);
  const std::vector<Vec3> b_world = ToWorld(*input.points_b, input.world_from_b);

  GjkResult result;
  Simplex simplex;
  Vec3 v = a_world[0] - b_world[0];
  Simplex best_simplex;
  best_simplex.vertices[0] = {v, a_world[0], b_world[0]};
  best_simplex.weights[0] = 1.0;
  best_simplex.count = 1;
  double max_point_squared = v.squaredNorm();
  bool overlapping = false;

  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    result.iterations = iteration + 1;
    const Vec3 support_a = a_world[Support(a_world, -v)];
    const Vec3 support_b = b_world[Support(b_world, v)];
    const Vec3 w = support_a - support_b;
    max_point_squared = std::max(max_point_squared, w.squaredNorm());
    const double v_squared = v.squaredNorm();
    const double gap = v_squared - v.dot(w);
    if (gap <= kRelativeTolerance * v_squared ||
        gap <= kAbsoluteTolerance * std::sqrt(v_squared * max_point_squared)) {
      break;
    }
    bool repeated = false;
    for (int i = 0; i < simplex.count; ++i) repeated = repeated || simplex.vertices[i].w == w;
    if (repeated) break;

    simplex.vertices[simplex.count++] = {w, support_a, support_b};
    overlapping = !ReduceSimplex(&simplex);
    if (overlapping) break;
    v = Vec3::Zero();
    for (int i = 0; i < simplex.count; ++i) v += simplex.weights[i] * simplex.vertices[i].w;
    const double new_squared = v.squaredNorm();
    if (new_squared <= kOverlapTolerance * kOverlapTolerance * max_point_squared) {
      overlapping = true;
      break;
    }
    // After the first iteration the new simplex contains the old closest
    // point's support feature, so |v| must shrink; if it does not, rounding
    // has taken over and the previous v is the answer.
    if (iteration > 0 && new_squared >= v_squared) break;
    best_simplex = simplex;
  }

  if (overlapping) {
    result.overlapping = true;
    result.distance = 0.0;
    return result;
  }
  SetClosestPoints(best_simplex, &result);
  return result;
}

}  // namespace rigid_body_sim::physics
