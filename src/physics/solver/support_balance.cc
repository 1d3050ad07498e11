#include "physics/solver/support_balance.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace rigid_body_sim::physics {

namespace {

// A point of a support, in world space, with its vertical load (N s).
struct LoadPoint {
  std::uint32_t support;
  int point;
  Vec3 position;
  double load;
};

// lambda_i = L / N + d_i . C^+ (L e) over the points still carrying; a
// point that would pull (lambda_i < 0, the load's line outside the middle of
// the support) is dropped and the rest solved again, as an active set
// method for the loads' least squares under lambda >= 0 would (Lawson and
// Hanson 1974, "Solving Least Squares Problems", chapter 23). What is left
// after kMostDrops rounds is clamped and scaled back to L.
void Spread(double total, const Vec3& load_centre, const Vec3& up, std::vector<LoadPoint>* points) {
  constexpr int kMostDrops = 4;
  const auto horizontal = [&](const Vec3& v) { return Vec3(v - v.dot(up) * up); };
  std::vector<char> carries(points->size(), 1);
  for (int round = 0; round <= kMostDrops; ++round) {
    Vec3 centroid = Vec3::Zero();
    int count = 0;
    for (std::size_t i = 0; i < points->size(); ++i) {
      if (carries[i] == 0) continue;
      centroid += (*points)[i].position;
      ++count;
    }
    centroid /= count;
    Mat3 spread = Mat3::Zero();
    for (std::size_t i = 0; i < points->size(); ++i) {
      const Vec3 d = horizontal((*points)[i].position - centroid);
      if (carries[i] != 0) spread += d * d.transpose();
    }
    const Vec3 beta = spread.completeOrthogonalDecomposition().solve(
        Vec3(total * horizontal(load_centre - centroid)));
    bool dropped = false;
    for (std::size_t i = 0; i < points->size(); ++i) {
      LoadPoint& p = (*points)[i];
      p.load = carries[i] == 0 ? 0.0 : total / count + horizontal(p.position - centroid).dot(beta);
      if (p.load < 0.0 && round < kMostDrops && count > 1) {
        carries[i] = 0;
        dropped = true;
      }
    }
    if (!dropped) break;
  }
  double sum = 0.0;
  for (LoadPoint& p : *points) {
    p.load = std::max(p.load, 0.0);
    sum += p.load;
  }
  if (sum <= 0.0) return;
  for (LoadPoint& p : *points) p.load *= total / sum;
}

}  // namespace

std::vector<UprightSupport> UprightSupportsHighestFirst(
    const SupportBalanceInput& input, const std::vector<SolverManifold>& manifolds) {
  std::vector<UprightSupport> supports;
  const double g = input.gravity.norm();
  if (g <= 0.0) return supports;
  // Most steps have no new pair at all: then no support is new, and the
  // supports need not be listed.
  bool any_new_pair = false;
  for (std::size_t m = 0; m < manifolds.size() && !any_new_pair; ++m) {
    any_new_pair = manifolds[m].new_pair && manifolds[m].point_count > 0;
  }
  if (!any_new_pair) return supports;
  const Vec3 up = -input.gravity / g;
  // A support is upright when its normal is within 60 degrees of up.
  constexpr double kUpright = 0.5;
  bool any_new = false;
  for (std::uint32_t m = 0; m < manifolds.size(); ++m) {
    const SolverManifold& manifold = manifolds[m];
    const double up_along_normal = manifold.normal_world.dot(up);  // the normal points to A
    if (std::abs(up_along_normal) <= kUpright || manifold.point_count == 0) continue;
    bool is_new = manifold.new_pair;
    for (int i = 0; i < manifold.point_count; ++i) {
      is_new &= manifold.points[i].separation <= input.contact_tolerance;
    }
    any_new |= is_new;
    if (up_along_normal > 0.0) {
      supports.push_back({m, manifold.body_a, manifold.body_b, is_new, up_along_normal});
    } else {
      supports.push_back({m, manifold.body_b, manifold.body_a, is_new, -up_along_normal});
    }
  }
  if (!any_new) {
    supports.clear();
    return supports;
  }
  // Ties by index, for the same order on every run. Each upper body's
  // height is read once, not at every comparison (a body load each).
  const std::vector<Body>& bodies = *input.bodies;
  std::vector<std::pair<double, UprightSupport>> by_height;
  by_height.reserve(supports.size());
  for (const UprightSupport& support : supports) {
    by_height.emplace_back(bodies[support.upper].position.dot(up), support);
  }
  std::sort(by_height.begin(), by_height.end(), [](const auto& x, const auto& y) {
    return x.first != y.first ? x.first > y.first : x.second.upper < y.second.upper;
  });
  for (std::size_t k = 0; k < supports.size(); ++k) supports[k] = by_height[k].second;
  return supports;
}

void BalanceNewSupports(const SupportBalanceInput& input,
                        const std::vector<UprightSupport>& supports,
                        std::vector<SolverManifold>* manifolds) {
  const std::vector<Body>& bodies = *input.bodies;
  const double g = input.gravity.norm();
  if (g <= 0.0 || supports.empty()) return;
  const Vec3 up = -input.gravity / g;
  // Per body: its vertical load (N s) and that load's moment, sum F x.
  std::vector<double> load(bodies.size(), 0.0);
  std::vector<Vec3> moment(bodies.size(), Vec3::Zero());
  for (const UprightSupport& s : supports) {
    load[s.upper] = bodies[s.upper].mass * g * input.dt;
    moment[s.upper] = load[s.upper] * bodies[s.upper].position;
  }
  std::vector<LoadPoint> points;
  for (std::size_t first = 0; first < supports.size();) {
    const std::uint32_t upper = supports[first].upper;
    std::size_t last = first;
    bool all_new = true;
    points.clear();
    for (; last < supports.size() && supports[last].upper == upper; ++last) {
      const UprightSupport& s = supports[last];
      all_new &= s.is_new;
      const SolverManifold& manifold = (*manifolds)[s.manifold];
      const Vec3& centre = bodies[manifold.body_a].position;
      for (int i = 0; i < manifold.point_count; ++i) {
        const SolverPoint& point = manifold.points[i];
        points.push_back({static_cast<std::uint32_t>(last), i, Vec3(centre + point.r_a),
                          point.normal_impulse * s.up_along_normal});
      }
    }
    if (all_new && CarriesLoad(bodies[upper]) && load[upper] > 0.0) {
      Spread(load[upper], moment[upper] / load[upper], up, &points);
      for (const LoadPoint& p : points) {
        const UprightSupport& s = supports[p.support];
        (*manifolds)[s.manifold].points[p.point].normal_impulse = p.load / s.up_along_normal;
      }
    }
    for (const LoadPoint& p : points) {
      const std::uint32_t lower = supports[p.support].lower;
      if (!CarriesLoad(bodies[lower])) continue;
      load[lower] += p.load;
      moment[lower] += p.load * p.position;
    }
    first = last;
  }
}

SupportBalanceInput SupportInputFor(const std::vector<Body>& bodies, const WorldSettings& settings,
                                    double dt) {
  SupportBalanceInput input;
  input.bodies = &bodies;
  input.gravity = settings.gravity;
  input.dt = dt;
  input.contact_tolerance = settings.solver.contact_tolerance;
  return input;
}

// A support that is new this step (a pair that had no contact point last
// step, and touches at every point now) starts the resting solve from the
// load it would carry at rest, instead of from zero. Statics of a stack,
// from the highest body down: a body's load is its weight m g dt plus the
// loads resting on it; the part its warm supports do not carry already
// (their impulses n / (n.up)) is shared equally by its new supports, whose
// points take the normal part n.up of their share; each support passes its
// load to the body below. Without it, Gauss-Seidel sweeps from zero move a
// load up a stack by about one level per sweep, so a stack spawned at rest
// sags and rocks for its first tenth of a second. The estimate is only
// where the iteration starts: the complementarity conditions, and so the
// solution, are the same. Returns the upright supports it walked (none when
// no support is new), for the soft step's spread.
std::vector<UprightSupport> SeedNewSupportLoads(const SupportBalanceInput& input,
                                                std::vector<SolverManifold>* solver_manifolds) {
  const double g = input.gravity.norm();
  if (g <= 0.0) return {};
  std::vector<SolverManifold>& manifolds = *solver_manifolds;
  const std::vector<Body>& bodies = *input.bodies;
  std::vector<UprightSupport> supports = UprightSupportsHighestFirst(input, manifolds);
  if (supports.empty()) return supports;
  // N s: a body's load; then, from its first support on, what its new
  // supports share.
  std::vector<double> load(bodies.size(), 0.0);
  std::vector<int> new_supports(bodies.size(), 0);
  for (const UprightSupport& support : supports) {
    load[support.upper] = bodies[support.upper].mass * g * input.dt;
    if (support.is_new) ++new_supports[support.upper];
  }
  auto warm_load = [&](const UprightSupport& support) {
    const SolverManifold& manifold = manifolds[support.manifold];
    double normal = 0.0;
    for (int i = 0; i < manifold.point_count; ++i) normal += manifold.points[i].normal_impulse;
    return normal / support.up_along_normal;
  };
  for (std::size_t k = 0; k < supports.size(); ++k) {
    const std::uint32_t upper = supports[k].upper;
    if (k == 0 || supports[k - 1].upper != upper) {
      for (std::size_t w = k; w < supports.size() && supports[w].upper == upper; ++w) {
        if (!supports[w].is_new) load[upper] -= warm_load(supports[w]);
      }
      load[upper] = std::max(load[upper], 0.0);
    }
    const UprightSupport& support = supports[k];
    double passed = 0.0;
    if (!support.is_new) {
      passed = warm_load(support);
    } else if (CarriesLoad(bodies[upper])) {
      passed = load[upper] / new_supports[upper];
      SolverManifold& manifold = manifolds[support.manifold];
      const double per_point = passed * support.up_along_normal / manifold.point_count;
      for (int i = 0; i < manifold.point_count; ++i) manifold.points[i].normal_impulse = per_point;
    }
    if (CarriesLoad(bodies[support.lower])) load[support.lower] += passed;
  }
  return supports;
}

}  // namespace rigid_body_sim::physics
