#include "measure.h"

#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <limits>
#include <memory>
#include <random>
#include <utility>

namespace rigid_body_sim::bench {
namespace {

// The velocity motors of a scene's articulations, joints numbered over all
// of them (Engine), the angle each one's commands add up to, and the
// driven joint's commanded angle.
class MotorSchedule {
 public:
  MotorSchedule(const Scene& scene, const Engine& engine)
      : driven_(scene.driven_joint), time_step_(scene.time_step) {
    int joint = 0;
    for (const BenchArticulation& articulation : scene.articulations) {
      for (std::size_t j = 0; j < articulation.joints.size(); ++j, ++joint) {
        if (j < articulation.motors.size() && !articulation.motors[j].empty()) {
          motors_.push_back(
              Motor{joint, articulation.motors[j], 0.0, false, engine.JointPosition(joint), 0.0});
        }
      }
    }
  }

  // Sets every motor's velocity for the step starting at time t (s).
  void Apply(double t, Engine* engine) {
    for (Motor& motor : motors_) {
      double velocity = motor.phases.front().velocity;
      for (const MotorPhase& phase : motor.phases) {
        if (phase.from_seconds <= t + 1e-9) velocity = phase.velocity;
      }
      if (!motor.set || velocity != motor.velocity) engine->SetMotorVelocity(motor.joint, velocity);
      motor.velocity = velocity;
      motor.set = true;
      motor.commanded += velocity * time_step_;
      if (motor.joint == driven_) commanded_ += velocity * time_step_;
    }
  }

  // rad: the largest distance of a motored joint from its start plus its
  // commands so far.
  double ServoError(const Engine& engine) const {
    double error = 0.0;
    for (const Motor& motor : motors_) {
      const double at = engine.JointPosition(motor.joint);
      error = std::max(error, std::abs(at - motor.start - motor.commanded));
    }
    return error;
  }

  double commanded() const { return commanded_; }  // rad, the driven joint's so far

 private:
  struct Motor {
    int joint;
    std::vector<MotorPhase> phases;
    double velocity;
    bool set;
    double start;      // rad
    double commanded;  // rad, the commands' sum so far
  };
  int driven_;
  double time_step_;  // s
  std::vector<Motor> motors_;
  double commanded_ = 0.0;
};

// The mechanical energy of an articulated run against its start, as
// fractions of the scene's EnergyScale.
class EnergyTracker {
 public:
  EnergyTracker(const Scene& scene, const Engine& engine)
      : scale_(std::max(EnergyScale(scene), 1e-9)), start_(engine.MechanicalEnergy()) {}

  void Observe(const Engine& engine) {
    const double energy = engine.MechanicalEnergy();
    if (!std::isfinite(energy)) {
      finite_ = false;
      return;
    }
    last_ = energy;
    growth_ = std::max(growth_, (energy - start_) / scale_);
  }

  void Finish(RunResult* result) const {
    constexpr double kInfinity = std::numeric_limits<double>::infinity();
    result->energy_start = start_;
    result->energy_drift = finite_ ? (last_ - start_) / scale_ : kInfinity;
    result->energy_growth = finite_ ? growth_ : kInfinity;
    result->diverged = !finite_ || !std::isfinite(start_) || growth_ > kDivergedGrowth;
  }

 private:
  double scale_;  // J
  double start_;  // J
  double last_ = start_;
  double growth_ = 0.0;
  bool finite_ = true;
};

// The first apex of a bounce: the highest point between leaving the ground
// and falling again.
struct ApexTracker {
  bool fell = false;
  bool rose = false;
  bool found = false;
  double highest = -1e300;

  void Observe(double z, double vz) {
    if (found) return;
    if (vz < -0.1) fell = true;
    if (fell && vz > 0.0) rose = true;
    if (rose) {
      highest = std::max(highest, z);
      if (vz <= 0.0) found = true;
    }
  }
};

void AddStageTimes(const Engine& engine, int step, int window_steps, double step_ms,
                   RunResult* result) {
  const StageTimes stages = engine.LastStageTimes();
  result->broad_phase_ms += stages.broad_phase_ms;
  result->narrow_phase_ms += stages.narrow_phase_ms;
  result->solver_ms += stages.solver_ms;
  result->integrator_ms += stages.integrator_ms;
  if (stages.solver_points > 0) {
    result->solver_point_iterations += static_cast<double>(stages.point_iterations);
    result->solver_rows_ms += stages.solver_ms;
    ++result->contact_steps;
    result->contact_steps_ms += step_ms;
    if (step < window_steps) {
      ++result->window_contact_steps;
      result->window_contact_ms += step_ms;
    }
  }
}

// The scene's figures from the engine's state at the end of the run.
void FinishRun(const Scene& scene, const Engine& engine, RunResult* result) {
  const double steps = result->steps;
  result->step_ms /= steps;
  result->broad_phase_ms /= steps;
  result->narrow_phase_ms /= steps;
  result->solver_ms /= steps;
  result->integrator_ms /= steps;
  result->final_kinetic_energy = engine.KineticEnergy();
  result->final_penetration = engine.MaxPenetration();
  if (scene.kind == SceneKind::kArmPush) {
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const Vec3 moved =
          engine.Position(static_cast<int>(i)) - scene.bodies[i].world_from_body.translation;
      result->boxes_moved += moved.head<2>().norm() > 0.01;
    }
  }
  if (scene.kind == SceneKind::kTerrain) {
    for (int i = 0; i < static_cast<int>(scene.bodies.size()); ++i) {
      const Vec3 position = engine.Position(i);
      result->below_surface += position.z() < scene.hills.HeightAt(position.x(), position.y());
    }
  }
  if (scene.top_body < 0) return;
  const Vec3 top_start = scene.bodies[scene.top_body].world_from_body.translation;
  const Vec3 top_end = engine.Position(scene.top_body);
  if (scene.kind == SceneKind::kPile) result->drift = (top_end - top_start).head<2>().norm();
  if (scene.kind == SceneKind::kPyramid) result->drift = (top_end - top_start).norm();
  if (scene.kind == SceneKind::kIncline) {
    const Vec3 downhill = scene.world_from_ground.rotation * Vec3::UnitX();
    result->slide = (top_end - top_start).dot(downhill);
  }
}

RunResult RunScene(const Scene& scene, EngineKind kind, const RunSettings& settings) {
  std::unique_ptr<Engine> engine = MakeEngine(kind, scene, settings.overrides);
  RunResult result;
  const double dt = scene.time_step;
  result.steps = static_cast<int>(std::lround(scene.seconds / dt));
  result.rows_per_point = engine->RowsPerPoint();
  const int window_steps =
      std::min(result.steps, static_cast<int>(std::lround(settings.window_seconds / dt)));
  const bool articulated = !scene.articulations.empty();
  MotorSchedule motors(scene, *engine);
  EnergyTracker energy(scene, *engine);
  ApexTracker apex;
  const double driven_start =
      scene.driven_joint >= 0 ? engine->JointPosition(scene.driven_joint) : 0.0;
  double total_ms = 0.0;
  using Clock = std::chrono::steady_clock;
  for (int step = 0; step < result.steps; ++step) {
    motors.Apply(step * dt, engine.get());
    const Clock::time_point start = Clock::now();
    engine->Step();
    const double step_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    total_ms += step_ms;
    if (step + 1 == window_steps) result.window_step_ms = total_ms / window_steps;
    AddStageTimes(*engine, step, window_steps, step_ms, &result);
    if (engine->AllMovingBodiesAwake()) {
      ++result.awake_steps;
      result.awake_ms += step_ms;
    }
    result.peak_penetration = std::max(result.peak_penetration, engine->MaxPenetration());
    if (articulated) {
      result.joint_separation = std::max(result.joint_separation, engine->JointAnchorSeparation());
      energy.Observe(*engine);
      result.servo_error = std::max(result.servo_error, motors.ServoError(*engine));
    }
    if (scene.driven_joint >= 0) {
      result.driven_swept =
          std::max(result.driven_swept, engine->JointPosition(scene.driven_joint) - driven_start);
      result.driven_commanded = std::max(result.driven_commanded, motors.commanded());
    }
    if (scene.kind == SceneKind::kBounce) {
      apex.Observe(engine->Position(0).z(), engine->LinearVelocity(0).z());
    }
    if (scene.kind == SceneKind::kTerrain) {
      for (int i = 0; i < static_cast<int>(scene.bodies.size()); ++i) {
        if (engine->LinearVelocity(i).norm() > 0.05) {
          result.settle_time = (step + 1) * dt;
          break;
        }
      }
    }
  }
  result.step_ms = total_ms;
  FinishRun(scene, *engine, &result);
  if (articulated) energy.Finish(&result);
  if (scene.kind == SceneKind::kBounce) {
    result.apex = apex.found ? apex.highest - scene.bodies[0].sphere_radius : 0.0;
  }
  result.ok = true;
  return result;
}

// Runs one scene in a child process; returns false when the child failed.
bool RunInChild(const Scene& scene, EngineKind kind, const RunSettings& settings,
                RunResult* result) {
  int fds[2];
  if (pipe(fds) != 0) return false;
  std::fflush(stdout);
  const pid_t pid = fork();
  if (pid < 0) return false;
  if (pid == 0) {
    close(fds[0]);
    const RunResult child_result = RunScene(scene, kind, settings);
    const ssize_t written = write(fds[1], &child_result, sizeof(child_result));
    _exit(written == static_cast<ssize_t>(sizeof(child_result)) ? 0 : 1);
  }
  close(fds[1]);
  RunResult received;
  std::size_t got = 0;
  while (got < sizeof(received)) {
    const ssize_t n =
        read(fds[0], reinterpret_cast<char*>(&received) + got, sizeof(received) - got);
    if (n <= 0) break;
    got += static_cast<std::size_t>(n);
  }
  close(fds[0]);
  int status = 0;
  struct rusage usage;
  std::memset(&usage, 0, sizeof(usage));
  wait4(pid, &status, 0, &usage);
  if (got != sizeof(received) || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return false;
  *result = received;
  result->peak_rss_kb = usage.ru_maxrss;
  return result->ok;
}

// The top box's drift in a pile is chaotic: a micrometre anywhere at the
// start changes it several-fold, in Bullet as in ours. Run 0 is the scene as
// defined; run k > 0 moves every free body by up to kJitter (uniform per
// axis, seed k, the same for every engine), and the drift reported is the
// median over the runs.
constexpr double kJitter = 1e-6;  // m

Scene JitterScene(const Scene& scene, int seed) {
  Scene jittered = scene;
  if (seed == 0) return jittered;
  std::mt19937 random(static_cast<std::uint32_t>(seed));
  std::uniform_real_distribution<double> offset(-kJitter, kJitter);
  for (BenchBody& body : jittered.bodies) {
    body.world_from_body.translation += Vec3(offset(random), offset(random), offset(random));
  }
  return jittered;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// Sums up one engine's runs of a scene (none when all failed).
Summary Summarize(const Scene& scene, EngineKind kind, std::vector<RunResult> results) {
  Summary summary;
  summary.scene = scene.name;
  summary.engine = EngineName(kind);
  summary.threads = EngineThreads(kind);
  summary.solver = EngineSolver(kind);
  summary.bodies = static_cast<int>(scene.bodies.size());
  for (const BenchArticulation& articulation : scene.articulations) {
    summary.bodies += static_cast<int>(articulation.links.size()) - 1;  // the moving links
  }
  summary.seconds = scene.seconds;
  summary.time_step = scene.time_step;
  if (results.empty()) return summary;
  for (const RunResult& result : results) summary.diverged_runs += result.diverged;
  // Each quality figure is the median over the runs on its own, so that it
  // does not depend on which run the machine happened to run fastest; the
  // times and the stage profile are those of the median run by time.
  constexpr double RunResult::*kQualityFigures[] = {&RunResult::final_kinetic_energy,
                                                    &RunResult::final_penetration,
                                                    &RunResult::peak_penetration,
                                                    &RunResult::drift,
                                                    &RunResult::apex,
                                                    &RunResult::slide,
                                                    &RunResult::joint_separation,
                                                    &RunResult::boxes_moved,
                                                    &RunResult::driven_swept,
                                                    &RunResult::driven_commanded,
                                                    &RunResult::settle_time,
                                                    &RunResult::below_surface,
                                                    &RunResult::energy_drift,
                                                    &RunResult::energy_growth,
                                                    &RunResult::energy_start,
                                                    &RunResult::servo_error};
  std::vector<double> medians;
  for (double RunResult::*figure : kQualityFigures) {
    std::vector<double> values;
    for (const RunResult& result : results) values.push_back(result.*figure);
    medians.push_back(Median(std::move(values)));
  }
  std::vector<double> awake;
  for (const RunResult& result : results) {
    if (result.awake_steps > 0) awake.push_back(AwakeStepMs(result));
    summary.peak_rss_kb = std::max(summary.peak_rss_kb, result.peak_rss_kb);
  }
  summary.awake_ms_median = Median(std::move(awake));
  std::sort(results.begin(), results.end(),
            [](const RunResult& a, const RunResult& b) { return a.step_ms < b.step_ms; });
  summary.median = results[results.size() / 2];
  for (std::size_t k = 0; k < medians.size(); ++k) {
    summary.median.*kQualityFigures[k] = medians[k];
  }
  summary.ms_median = summary.median.step_ms;
  summary.ms_min = results.front().step_ms;
  summary.ms_max = results.back().step_ms;
  return summary;
}

}  // namespace

std::string EngineLabel(const Summary& summary) {
  std::string label = summary.engine;
  if (summary.solver == "soft_step") label += " soft_step";
  if (summary.threads > 1) label += " x" + std::to_string(summary.threads);
  return label;
}

namespace {

// Appends this run's ms per step and per awake step of engine `mine` over
// engine `other`'s, where both ran and measured them.
void AddRatios(const RunResult& mine, const RunResult& other, std::vector<double>* ratios,
               std::vector<double>* awake_ratios) {
  if (other.step_ms > 0.0) ratios->push_back(mine.step_ms / other.step_ms);
  if (AwakeStepMs(mine) > 0.0 && AwakeStepMs(other) > 0.0) {
    awake_ratios->push_back(AwakeStepMs(mine) / AwakeStepMs(other));
  }
}

// One of ours, as the numerator of a pair of ratio columns of every other
// engine's row (Summary).
struct RatioNumerator {
  EngineKind kind;
  double Summary::*over_this;
  double Summary::*over_this_awake;
};

constexpr RatioNumerator kRatioNumerators[] = {
    {EngineKind::kOurs, &Summary::ours_over_this, &Summary::ours_over_this_awake},
    {EngineKind::kOursTwoThreads, &Summary::ours2_over_this, &Summary::ours2_over_this_awake},
    {EngineKind::kOursSoft, &Summary::soft_over_this, &Summary::soft_over_this_awake},
    {EngineKind::kOursSoftTwoThreads, &Summary::soft2_over_this, &Summary::soft2_over_this_awake},
};
constexpr std::size_t kNumerators = std::size(kRatioNumerators);

// One numerator's ratios to each engine, run by run.
struct RunRatios {
  std::vector<std::vector<double>> step;   // per engine
  std::vector<std::vector<double>> awake;  // per engine
};

}  // namespace

std::vector<Summary> MeasureEngines(const Scene& scene, int runs, const RunSettings& settings,
                                    const std::vector<EngineKind>& engines) {
  const std::size_t count = engines.size();
  std::vector<std::vector<RunResult>> results(count);
  // Where each numerator is among `engines`; count when it is not there.
  std::size_t numerator_at[kNumerators];
  std::vector<RunRatios> ratios(kNumerators);
  for (std::size_t n = 0; n < kNumerators; ++n) {
    numerator_at[n] = static_cast<std::size_t>(
        std::find(engines.begin(), engines.end(), kRatioNumerators[n].kind) - engines.begin());
    ratios[n].step.resize(count);
    ratios[n].awake.resize(count);
  }
  for (int run = 0; run < runs; ++run) {
    const Scene jittered = JitterScene(scene, run);
    std::vector<RunResult> this_run(count);
    std::vector<bool> ok(count);
    for (std::size_t e = 0; e < count; ++e) {
      ok[e] = RunInChild(jittered, engines[e], settings, &this_run[e]);
      if (ok[e]) {
        results[e].push_back(this_run[e]);
      } else {
        std::fprintf(stderr, "%s/%s: run %d failed\n", scene.name.c_str(),
                     EngineName(engines[e]).c_str(), run);
      }
    }
    // A run that diverged is no ratio's denominator, nor its numerator:
    // an engine that blew up measured the time of another computation.
    for (std::size_t e = 0; e < count; ++e) ok[e] = ok[e] && !this_run[e].diverged;
    // Each of ours that ran: its ratio to each other engine in this run.
    for (std::size_t n = 0; n < kNumerators; ++n) {
      const std::size_t mine = numerator_at[n];
      if (mine >= count || !ok[mine]) continue;
      for (std::size_t e = 0; e < count; ++e) {
        if (ok[e] && e != mine) {
          AddRatios(this_run[mine], this_run[e], &ratios[n].step[e], &ratios[n].awake[e]);
        }
      }
    }
  }
  std::vector<Summary> summaries;
  for (std::size_t e = 0; e < count; ++e) {
    summaries.push_back(Summarize(scene, engines[e], std::move(results[e])));
    for (std::size_t n = 0; n < kNumerators; ++n) {
      summaries.back().*kRatioNumerators[n].over_this = Median(std::move(ratios[n].step[e]));
      summaries.back().*kRatioNumerators[n].over_this_awake = Median(std::move(ratios[n].awake[e]));
    }
  }
  return summaries;
}

}  // namespace rigid_body_sim::bench
