#include "rigid_body_sim/node/joint_trajectory.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace rigid_body_sim::node {

using physics::FormatNumber;
using physics::Result;

Result<JointTrajectory> JointTrajectory::Make(const TrajectoryPoint& start,
                                              std::vector<TrajectoryPoint> points) {
  const std::size_t joints = start.positions.size();
  if (points.empty()) return Result<JointTrajectory>::Error("the trajectory has no points");
  JointTrajectory trajectory;
  if (points.front().time > 0.0) trajectory.points_.push_back(start);
  double previous = -1.0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const TrajectoryPoint& point = points[k];
    const std::string where = "point " + std::to_string(k);
    if (!std::isfinite(point.time) || point.time < 0.0 || point.time <= previous) {
      return Result<JointTrajectory>::Error(
          where + " time_from_start " + FormatNumber(point.time) +
          " s must be finite, >= 0 and later than the point before");
    }
    previous = point.time;
    if (point.positions.size() != joints ||
        (!point.velocities.empty() && point.velocities.size() != joints)) {
      return Result<JointTrajectory>::Error(
          where + " needs " + std::to_string(joints) + " positions (and no or " +
          std::to_string(joints) + " velocities), has " + std::to_string(point.positions.size()) +
          " and " + std::to_string(point.velocities.size()));
    }
    for (std::size_t j = 0; j < joints; ++j) {
      const double v = point.velocities.empty() ? 0.0 : point.velocities[j];
      if (!std::isfinite(point.positions[j]) || !std::isfinite(v)) {
        return Result<JointTrajectory>::Error(where + " has a value that is not finite");
      }
    }
    trajectory.points_.push_back(point);
  }
  std::vector<TrajectoryPoint>& all = trajectory.points_;
  if (all.front().velocities.empty()) all.front().velocities.assign(joints, 0.0);
  for (std::size_t k = 1; k < all.size(); ++k) {
    if (!all[k].velocities.empty()) continue;
    all[k].velocities.assign(joints, 0.0);
    if (k + 1 == all.size()) continue;
    for (std::size_t j = 0; j < joints; ++j) {
      const double before =
          (all[k].positions[j] - all[k - 1].positions[j]) / (all[k].time - all[k - 1].time);
      const double after =
          (all[k + 1].positions[j] - all[k].positions[j]) / (all[k + 1].time - all[k].time);
      all[k].velocities[j] = 0.5 * (before + after);
    }
  }
  return trajectory;
}

// Cubic Hermite interpolation on [t0, t1] with s = (t - t0) / h:
// p(s) = h00 p0 + h10 h v0 + h01 p1 + h11 h v1, h00 = 2s^3 - 3s^2 + 1,
// h10 = s^3 - 2s^2 + s, h01 = -2s^3 + 3s^2, h11 = s^3 - s^2; its velocity
// is dp/ds / h (de Boor 1978, "A Practical Guide to Splines", chapter IV).
TrajectorySample JointTrajectory::Sample(double t) const {
  TrajectorySample sample;
  if (t >= points_.back().time) {
    sample.positions = points_.back().positions;
    sample.velocities = t == points_.back().time
                            ? points_.back().velocities
                            : std::vector<double>(sample.positions.size(), 0.0);
    return sample;
  }
  t = std::max(t, points_.front().time);
  std::size_t k = 0;
  while (points_[k + 1].time < t) ++k;
  const TrajectoryPoint& a = points_[k];
  const TrajectoryPoint& b = points_[k + 1];
  const double h = b.time - a.time;
  const double s = (t - a.time) / h;
  const double s2 = s * s;
  const double s3 = s2 * s;
  for (std::size_t j = 0; j < a.positions.size(); ++j) {
    const double p0 = a.positions[j];
    const double p1 = b.positions[j];
    const double m0 = h * a.velocities[j];
    const double m1 = h * b.velocities[j];
    sample.positions.push_back((2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 +
                               (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1);
    sample.velocities.push_back(((6 * s2 - 6 * s) * p0 + (3 * s2 - 4 * s + 1) * m0 +
                                 (-6 * s2 + 6 * s) * p1 + (3 * s2 - 2 * s) * m1) /
                                h);
  }
  return sample;
}

}  // namespace rigid_body_sim::node
