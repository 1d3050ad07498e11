// /diagnostics of the simulator through diagnostic_updater: per window of
// wall time, the mean and longest step time, the achieved real-time factor
// against the target, awake bodies, contacts and the solver's effort.
#ifndef RIGID_BODY_SIM_NODE_SIM_DIAGNOSTICS_H_
#define RIGID_BODY_SIM_NODE_SIM_DIAGNOSTICS_H_

#include <chrono>
#include <cstdint>
#include <mutex>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::node {

// The world's state when a window closes.
struct WorldSnapshot {
  double sim_time = 0.0;    // s
  double target_rtf = 1.0;  // the ~real_time_factor asked for; 0 = flat out
  bool paused = false;
  std::size_t bodies = 0;    // models
  std::size_t awake = 0;     // dynamic bodies being integrated
  std::size_t contacts = 0;  // contact points of the last step
};

// What one window of wall time saw.
struct DiagnosticsWindow {
  double wall_seconds = 0.0;
  double sim_seconds = 0.0;
  std::uint64_t steps = 0;
  double step_seconds_sum = 0.0;
  double step_seconds_max = 0.0;
  int velocity_sweeps_max = 0;        // of the slowest island, over the window's steps
  std::size_t solver_points_max = 0;  // contact points handed to the solver in one step
  WorldSnapshot world;
};

// A window whose achieved real-time factor is below this fraction of the
// target (while running and paced) is a WARN.
inline constexpr double kRealTimeFactorTolerance = 0.9;

// Fills `status` from a window: WARN when the target real-time factor is not
// held, OK otherwise. ROS-free apart from the status wrapper.
void FillDiagnostics(const DiagnosticsWindow& window,
                     diagnostic_updater::DiagnosticStatusWrapper* status);

// Thread-safe: steps are recorded by the loop under the world lock, the
// window is closed there too, and Publish runs outside it.
class SimDiagnostics {
 public:
  using Clock = std::chrono::steady_clock;

  SimDiagnostics(ros::NodeHandle node, ros::NodeHandle private_node);

  void RecordStep(double step_seconds, const physics::StepProfile& profile);
  // Ends the current window at `now` with the world's state; the next
  // starts there. Sim time going backwards (a reset) counts as 0 s.
  void CloseWindow(const WorldSnapshot& world, Clock::time_point now);
  // Publishes the last closed window on /diagnostics.
  void Publish();
  // s of wall time between windows (the updater's ~diagnostic_period, 1 s).
  double period() { return updater_.getPeriod(); }

 private:
  std::mutex mutex_;
  DiagnosticsWindow current_;
  DiagnosticsWindow closed_;
  Clock::time_point window_start_ = Clock::now();
  double window_start_sim_ = 0.0;
  diagnostic_updater::Updater updater_;
};

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_SIM_DIAGNOSTICS_H_
