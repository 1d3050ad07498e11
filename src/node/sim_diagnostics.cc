#include "rigid_body_sim/node/sim_diagnostics.h"

#include <algorithm>
#include <utility>

namespace rigid_body_sim::node {

void FillDiagnostics(const DiagnosticsWindow& window,
                     diagnostic_updater::DiagnosticStatusWrapper* status) {
  const double achieved =
      window.wall_seconds > 0.0 ? window.sim_seconds / window.wall_seconds : 0.0;
  const double mean_ms =
      window.steps > 0 ? 1e3 * window.step_seconds_sum / static_cast<double>(window.steps) : 0.0;
  const WorldSnapshot& world = window.world;
  if (world.paused) {
    status->summary(diagnostic_msgs::DiagnosticStatus::OK, "paused");
  } else if (world.target_rtf > 0.0 && achieved < kRealTimeFactorTolerance * world.target_rtf) {
    status->summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                     "real-time factor %.3g cannot be held: achieved %.3g (steps take %.3g ms)",
                     world.target_rtf, achieved, mean_ms);
  } else {
    status->summaryf(diagnostic_msgs::DiagnosticStatus::OK, "running at real-time factor %.3g",
                     achieved);
  }
  status->add("sim time (s)", world.sim_time);
  status->add("real-time factor achieved", achieved);
  status->add("real-time factor target (0: flat out)", world.target_rtf);
  status->add("steps in window", window.steps);
  status->add("step time mean (ms)", mean_ms);
  status->add("step time max (ms)", 1e3 * window.step_seconds_max);
  status->add("models", world.bodies);
  status->add("awake bodies", world.awake);
  status->add("contacts", world.contacts);
  status->add("solver sweeps max (slowest island)", window.velocity_sweeps_max);
  status->add("solver contact points max", window.solver_points_max);
  // The Gauss-Seidel solver does not report its residual; its sweep count
  // against ~solver/velocity_iterations says whether it converged.
}

SimDiagnostics::SimDiagnostics(ros::NodeHandle node, ros::NodeHandle private_node)
    : updater_(std::move(node), std::move(private_node)) {
  updater_.setHardwareID("none");
  updater_.add("physics", [this](diagnostic_updater::DiagnosticStatusWrapper& status) {
    std::lock_guard<std::mutex> lock(mutex_);
    FillDiagnostics(closed_, &status);
  });
}

void SimDiagnostics::RecordStep(double step_seconds, const physics::StepProfile& profile) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++current_.steps;
  current_.step_seconds_sum += step_seconds;
  current_.step_seconds_max = std::max(current_.step_seconds_max, step_seconds);
  current_.velocity_sweeps_max = std::max(current_.velocity_sweeps_max, profile.velocity_sweeps);
  current_.solver_points_max = std::max(current_.solver_points_max, profile.solver_points);
}

void SimDiagnostics::CloseWindow(const WorldSnapshot& world, Clock::time_point now) {
  std::lock_guard<std::mutex> lock(mutex_);
  current_.wall_seconds = std::chrono::duration<double>(now - window_start_).count();
  current_.sim_seconds = std::max(0.0, world.sim_time - window_start_sim_);
  current_.world = world;
  closed_ = current_;
  current_ = DiagnosticsWindow{};
  window_start_ = now;
  window_start_sim_ = world.sim_time;
}

void SimDiagnostics::Publish() { updater_.force_update(); }

}  // namespace rigid_body_sim::node
