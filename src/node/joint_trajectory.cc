#include "rigid_body_sim/node/joint_trajectory.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace rigid_body_sim::node {

using physics::FormatNumber;
using physics::Result;
using physics::Status;

namespace {

// The mean of the slopes to the neighbouring points, the velocity a point
// without one is given (Catmull-Rom-like, on uneven times).
void EstimateVelocity(const TrajectoryPoint& before, const TrajectoryPoint& after,
                      TrajectoryPoint* point) {
  point->velocities.resize(point->positions.size());
  for (std::size_t j = 0; j < point->positions.size(); ++j) {
    const double slope_before =
        (point->positions[j] - before.positions[j]) / (point->time - before.time);
    const double slope_after =
        (after.positions[j] - point->positions[j]) / (after.time - point->time);
    point->velocities[j] = 0.5 * (slope_before + slope_after);
  }
}

}  // namespace

Result<JointTrajectory> JointTrajectory::Plan(std::size_t joints,
                                              std::vector<TrajectoryPoint> points) {
  if (points.empty()) return Result<JointTrajectory>::Error("the trajectory has no points");
  double previous = -1.0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const TrajectoryPoint& point = points[k];
    const std::string where = "point " + std::to_string(k);
    // Points closer than kMinPointGap would make the slopes between them,
    // and so the commanded velocities, overflow (2e4 rad over 1e-300 s).
    // The gap is a difference, not previous + gap: far from 0 the sum
    // rounds back to previous and two points could share one time.
    const bool too_close = k == 0 ? point.time > 0.0 && point.time < kMinPointGap
                                  : !(point.time - previous >= kMinPointGap);
    if (!(point.time >= 0.0 && point.time <= kMaxPointTime) || too_close) {
      return Result<JointTrajectory>::Error(where + " time_from_start " + FormatNumber(point.time) +
                                            " s must be in [0, " + FormatNumber(kMaxPointTime) +
                                            "] and at least " + FormatNumber(kMinPointGap) +
                                            " s later than the point before (or the start)");
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
  }
  JointTrajectory trajectory;
  trajectory.first_velocity_given_ = !points.front().velocities.empty();
  // Interior points depend only on their neighbours among the points; the
  // first one's estimate waits for the start (Begin), the last one rests.
  for (std::size_t k = 1; k + 1 < points.size(); ++k) {
    if (points[k].velocities.empty()) EstimateVelocity(points[k - 1], points[k + 1], &points[k]);
  }
  if (points.size() > 1 && points.back().velocities.empty()) {
    points.back().velocities.assign(joints, 0.0);
  }
  trajectory.points_ = std::move(points);
  return trajectory;
}

Status JointTrajectory::Begin(const TrajectoryPoint& start) {
  const std::size_t joints = points_.front().positions.size();
  if (start.positions.size() != joints ||
      (!start.velocities.empty() && start.velocities.size() != joints)) {
    return Status::Error("the start needs " + std::to_string(joints) + " positions, has " +
                         std::to_string(start.positions.size()));
  }
  if (points_.front().time > 0.0) {
    points_.insert(points_.begin(), start);
    if (points_.front().velocities.empty()) points_.front().velocities.assign(joints, 0.0);
    if (!first_velocity_given_) {
      if (points_.size() > 2) {
        EstimateVelocity(points_[0], points_[2], &points_[1]);
      } else {
        points_[1].velocities.assign(joints, 0.0);
      }
    }
  } else if (!first_velocity_given_) {
    points_.front().velocities.assign(joints, 0.0);
  }
  return Status::Ok();
}

Result<JointTrajectory> JointTrajectory::Make(const TrajectoryPoint& start,
                                              std::vector<TrajectoryPoint> points) {
  Result<JointTrajectory> trajectory = Plan(start.positions.size(), std::move(points));
  if (!trajectory.ok()) return trajectory;
  if (Status status = trajectory.value().Begin(start); !status.ok()) return status;
  return trajectory;
}

// Cubic Hermite interpolation on [t0, t1] with s = (t - t0) / h:
// p(s) = h00 p0 + h10 h v0 + h01 p1 + h11 h v1, h00 = 2s^3 - 3s^2 + 1,
// h10 = s^3 - 2s^2 + s, h01 = -2s^3 + 3s^2, h11 = s^3 - s^2; its velocity
// is dp/ds / h (de Boor 1978, "A Practical Guide to Splines", chapter IV).
TrajectorySample JointTrajectory::Sample(double t) const {
  TrajectorySample sample;
  // Before the first point (and NaN) is the first point; a trajectory of
  // one point at time 0 then takes the branch below.
  if (!(t >= points_.front().time)) t = points_.front().time;
  if (t >= points_.back().time) {
    sample.positions = points_.back().positions;
    sample.velocities = t == points_.back().time
                            ? points_.back().velocities
                            : std::vector<double>(sample.positions.size(), 0.0);
    return sample;
  }
  // The segment [k, k + 1] holding t, by bisection: a trajectory may have
  // up to ~max_trajectory_points points and is sampled every step.
  const auto after =
      std::lower_bound(points_.begin() + 1, points_.end(), t,
                       [](const TrajectoryPoint& point, double time) { return point.time < time; });
  const std::size_t k = static_cast<std::size_t>(after - points_.begin()) - 1;
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
