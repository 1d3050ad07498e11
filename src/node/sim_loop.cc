// The node's step loop: steps at the real-time factor, or flat out, and
// hands what is due to Publish.
#include <algorithm>
#include <cassert>
#include <chrono>
#include <exception>
#include <string>

#include "node/model_sensors.h"
#include "rigid_body_sim/node/sim_node.h"

namespace rigid_body_sim::node {

using physics::Status;

namespace {

// A sim loop that falls this far behind its real-time schedule stops trying
// to catch up and restarts its schedule, so it never steps in bursts.
constexpr double kMaxLagSeconds = 0.1;
// /clock is published at most this often (s of real time) while stepping.
constexpr double kClockPeriodSeconds = 0.001;

}  // namespace

void SimNode::StepLocked() {
  for (ActiveWrench& wrench : wrenches_) {
    Status status = world_.ApplyForceAtPoint(wrench.body, wrench.force_world, wrench.point_world);
    assert(status.ok());
    status = world_.ApplyTorque(wrench.body, wrench.torque_world);
    assert(status.ok());
    --wrench.remaining_steps;
  }
  wrenches_.erase(std::remove_if(wrenches_.begin(), wrenches_.end(),
                                 [](const ActiveWrench& w) { return w.remaining_steps <= 0; }),
                  wrenches_.end());
  FollowTrajectoriesLocked();
  BeforeStepSensorsLocked();
  const Clock::time_point start = Clock::now();
  world_.Step();
  diagnostics_->RecordStep(std::chrono::duration<double>(Clock::now() - start).count(),
                           world_.last_step_profile());
  ++steps_;
  if (!world_.non_finite_bodies().empty()) ReportFrozenLocked();
  AfterStepSensorsLocked();
}

void SimNode::ReportFrozenLocked() {
  for (const physics::BodyId body : world_.non_finite_bodies()) {
    wrenches_.erase(std::remove_if(wrenches_.begin(), wrenches_.end(),
                                   [body](const ActiveWrench& w) { return w.body == body; }),
                    wrenches_.end());
    const Model* model = registry_.FindByBody(body);
    const std::string name = model != nullptr ? model->name : "(unnamed body)";
    frozen_models_.insert(name);
    ROS_ERROR(
        "model '%s' frozen at sim time %.6f s: its state stopped being finite or grew beyond "
        "1e100; held at its last finite pose, out of the simulation, until ~set_state or ~reset",
        name.c_str(), world_.time());
  }
}

void SimNode::ReanchorLocked() {
  anchor_wall_ = Clock::now();
  anchor_sim_ = world_.time();
}

void SimNode::StepLoop() {
  const auto clock_period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(kClockPeriodSeconds));
  const auto status_period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(options_.status_period));
  Clock::time_point next_clock = Clock::now();
  Clock::time_point next_status = Clock::now() + status_period;
  const auto diagnostics_period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(diagnostics_->period()));
  Clock::time_point next_diagnostics = Clock::now() + diagnostics_period;
  for (;;) {
    Outbox outbox;
    try {
      std::unique_lock<std::mutex> lock(mutex_);
      if (shutdown_) return;
      if (paused_) {
        wake_.wait_until(lock, next_publish_, [this] { return shutdown_ || !paused_; });
        if (shutdown_) return;
      } else if (live_.real_time_factor > 0.0) {
        // Real-time pacing: the next step is due when the wall clock has
        // caught up with sim time / real_time_factor.
        const auto due = anchor_wall_ +
                         std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                             (world_.time() - anchor_sim_) / live_.real_time_factor));
        if (Clock::now() < due) {
          const auto wake_at = std::min(due, next_publish_);
          const auto anchor = anchor_wall_;
          wake_.wait_until(lock, wake_at,
                           [&] { return shutdown_ || paused_ || anchor_wall_ != anchor; });
          if (shutdown_) return;
        } else if (Clock::now() - due > std::chrono::duration<double>(kMaxLagSeconds)) {
          ReanchorLocked();
        }
        if (!paused_ && Clock::now() >= due) StepLocked();
      } else {
        StepLocked();
      }
      const Clock::time_point now = Clock::now();
      if (!FillPeriodicIfDueLocked(now, &outbox) && options_.use_sim_time && now >= next_clock &&
          world_.time() > 0.0) {
        outbox.clock = world_.time();
      }
      if (outbox.clock) next_clock = now + clock_period;
      outbox.sensors.swap(pending_sensor_messages_);
      if (now >= next_status) {
        LogStatusLocked(now);
        next_status = now + status_period;
      }
      if (now >= next_diagnostics) {
        CloseDiagnosticsWindowLocked(now);
        outbox.diagnostics = true;
        next_diagnostics = now + diagnostics_period;
      }
    } catch (const std::exception& error) {
      // Stepping on would likely throw again at once; pausing keeps the
      // node answering, and ~set_paused resumes.
      std::lock_guard<std::mutex> lock(mutex_);
      paused_ = true;
      ROS_ERROR("step loop: %s; simulation paused", error.what());
      continue;
    }
    try {
      Publish(std::move(outbox));
    } catch (const std::exception& error) {
      ROS_ERROR_THROTTLE(5.0, "publishing: %s", error.what());
    }
    // Service callers waiting for the mutex go first, so a flat-out loop
    // cannot starve them.
    while (waiting_.load(std::memory_order_acquire) > 0) std::this_thread::yield();
  }
}

void SimNode::CloseDiagnosticsWindowLocked(Clock::time_point now) {
  WorldSnapshot snapshot;
  snapshot.sim_time = world_.time();
  snapshot.target_rtf = live_.real_time_factor;
  snapshot.paused = paused_;
  snapshot.bodies = registry_.size();
  snapshot.awake = world_.AwakeBodyCount();
  snapshot.contacts = world_.contacts().size();
  diagnostics_->CloseWindow(snapshot, now);
}

void SimNode::LogStatusLocked(Clock::time_point now) {
  const double wall = std::chrono::duration<double>(now - status_wall_).count();
  const double achieved = wall > 0.0 ? (world_.time() - status_sim_) / wall : 0.0;
  std::size_t static_models = 0;
  for (const auto& [name, model] : registry_.models()) static_models += model.is_static ? 1 : 0;
  // Models and bodies are counted apart: a robot is one model of many bodies.
  ROS_INFO(
      "sim time %.3f s, real-time factor %.2f%s, models %zu (%zu static), bodies %zu "
      "(%zu awake), contacts %zu",
      world_.time(), achieved, paused_ ? " (paused)" : "", registry_.size(), static_models,
      world_.BodyCount(), world_.AwakeBodyCount(), world_.contacts().size());
  status_wall_ = now;
  status_sim_ = world_.time();
}

}  // namespace rigid_body_sim::node
