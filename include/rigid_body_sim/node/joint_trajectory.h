// A joint trajectory followed in sim time: points with positions and
// (optionally) velocities, interpolated by cubic Hermite segments, so the
// commanded position is continuous in velocity. ROS-free.
#ifndef RIGID_BODY_SIM_NODE_JOINT_TRAJECTORY_H_
#define RIGID_BODY_SIM_NODE_JOINT_TRAJECTORY_H_

#include <vector>

#include "rigid_body_sim/physics/result.h"

namespace rigid_body_sim::node {

struct TrajectoryPoint {
  double time = 0.0;               // s from the trajectory's start
  std::vector<double> positions;   // rad or m, one per joint
  std::vector<double> velocities;  // rad/s or m/s, one per joint, or empty
};

struct TrajectorySample {
  std::vector<double> positions;
  std::vector<double> velocities;
};

class JointTrajectory {
 public:
  // s: the least time between two points, and from the start to the first
  // point unless it is at 0. ROS trajectories come at most at some kHz.
  static constexpr double kMinPointGap = 1e-6;
  // s: the latest time_from_start, the span of a ROS duration (2^31 s).
  // It also keeps kMinPointGap above the doubles' spacing (4.8e-7 s at
  // 2^31 s), so two points never share a time, and h * v in Sample finite.
  static constexpr double kMaxPointTime = 2147483648.0;

  // `start` holds the joints' positions and velocities when the trajectory
  // begins (time 0); `points` must have times up to kMaxPointTime increasing
  // by at least kMinPointGap (a first point at time 0 replaces the start) and one
  // finite value per joint. Velocities left out are estimated: the mean of the slopes to
  // the neighbouring points, 0 at the last point.
  static physics::Result<JointTrajectory> Make(const TrajectoryPoint& start,
                                               std::vector<TrajectoryPoint> points);
  // Make in two parts, so that the costly one needs no world: Plan checks
  // and prepares `points` for `joints` joints (O(points x joints)), Begin
  // puts the start in front (O(joints)); Sample only after Begin.
  static physics::Result<JointTrajectory> Plan(std::size_t joints,
                                               std::vector<TrajectoryPoint> points);
  physics::Status Begin(const TrajectoryPoint& start);

  // The commanded positions and velocities at time t (s from the start);
  // after the last point, its positions at rest.
  TrajectorySample Sample(double t) const;
  double duration() const { return points_.back().time; }

 private:
  std::vector<TrajectoryPoint> points_;  // the start first, after Begin
  bool first_velocity_given_ = false;    // points[0] came with velocities
};

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_JOINT_TRAJECTORY_H_
