// Runs the benchmark scenes (scene.h) in our engine and in Bullet, and
// prints per scene and engine the wall time per step (median of the runs,
// with min and max), steps per second, the quality figures, the ratio
// ours/Bullet, the time per stage, the cost per contact row per solver
// iteration and the peak memory. Writes the rows to a CSV file.
//
// Each run is a child process (fork), so its peak resident memory is its
// own (wait4's ru_maxrss) and no run inherits another's allocator state.
// The two engines' runs alternate, and the ratio is the median of the
// ratios of runs made back to back, as the machines are shared and their
// load drifts over minutes.
//
// Usage: physics_bench [--csv PATH] [--runs N] [--large-runs N] [--scale S]
//                      [--only a,b]
//                      [--hull-bench PATH]
//                      [--velocity-iterations N] [--time-to-sleep S]
//                      [--velocity-tolerance V] [--interleave-independent-runs 0|1]
//   --scale S multiplies the simulated time of pile_4000 and pyramid_90,
//   the two scenes that dominate the run time, and --large-runs N sets
//   their number of runs. --velocity-iterations, --time-to-sleep (s),
//   --velocity-tolerance (m/s) and --interleave-independent-runs run our
//   engine with those solver and sleep settings instead of the defaults, to
//   measure what a setting costs or buys; the header says so.

#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "engine.h"
#include "scene.h"

namespace rigid_body_sim::bench {
namespace {

constexpr double kGravity = 9.81;  // m/s^2

// What one run measures; plain data, sent from the child through a pipe.
struct RunResult {
  bool ok = false;
  int steps = 0;
  double step_ms = 0.0;         // wall ms per step, mean over the run
  double window_step_ms = 0.0;  // the same over the first window_seconds of the run
  // The steps with contact points within that window, and their wall time.
  int window_contact_steps = 0;
  double window_contact_ms = 0.0;
  double broad_phase_ms = 0.0;  // per step, mean
  double narrow_phase_ms = 0.0;
  double solver_ms = 0.0;
  double integrator_ms = 0.0;
  double solver_point_iterations = 0.0;  // sum over steps of points x iterations
  double solver_rows_ms = 0.0;           // solver time of the steps that had contact points
  // Steps with contact points to solve, and their wall time in all; sleeping
  // and free flight make the rest of a run nearly free in either engine.
  int contact_steps = 0;
  double contact_steps_ms = 0.0;
  int rows_per_point = 0;
  double final_kinetic_energy = 0.0;  // J
  double final_penetration = 0.0;     // m, deepest point at the last step
  double peak_penetration = 0.0;      // m, deepest point over the run
  double drift = 0.0;                 // m, top box (SceneKind)
  double apex = 0.0;                  // m, bounce: first apex above the resting height
  double slide = 0.0;                 // m, incline: distance slid down the slope
  // Terrain: s until no body moved faster than 0.05 m/s (the sleep
  // threshold) any more, and the bodies whose centre ended below the surface.
  double settle_time = 0.0;
  double below_surface = 0.0;
  long peak_rss_kb = 0;  // filled in by the parent
};

struct Summary {
  std::string scene;
  std::string engine;
  int bodies = 0;
  double seconds = 0.0;
  RunResult median;  // the median run by time, with each quality figure's median
  double ms_median = 0.0;
  double ms_min = 0.0;
  double ms_max = 0.0;
  long peak_rss_kb = 0;  // largest over the runs
  // Ours only: the median over the runs of ours/Bullet ms per step, each
  // pair run back to back (MeasureBoth); 0 when not measured.
  double ratio_to_bullet = 0.0;
};

// Wall ms of one step that had contact points to solve.
double ContactStepMs(const RunResult& result) {
  return result.contact_steps > 0 ? result.contact_steps_ms / result.contact_steps : 0.0;
}

// How every run of a benchmark is made.
struct RunSettings {
  double window_seconds = 10.0;  // s; the stage profile's window (RunResult)
  OurSettingsOverrides overrides;
};

RunResult RunScene(const Scene& scene, bool bullet, const RunSettings& settings) {
  std::unique_ptr<Engine> engine =
      bullet ? MakeBulletEngine(scene) : MakeOurEngine(scene, settings.overrides);
  const double window_seconds = settings.window_seconds;
  RunResult result;
  result.steps = static_cast<int>(std::lround(scene.seconds / kTimeStep));
  result.rows_per_point = engine->RowsPerPoint();
  const int top = scene.top_body;
  const Vec3 top_start = scene.bodies[top].world_from_body.translation;
  double total_ms = 0.0;
  const int window_steps =
      std::min(result.steps, static_cast<int>(std::lround(window_seconds / kTimeStep)));
  bool fell = false;
  bool rose = false;
  bool apex_found = false;
  double highest = -1e300;
  int last_moving_step = -1;
  using Clock = std::chrono::steady_clock;
  for (int step = 0; step < result.steps; ++step) {
    const Clock::time_point start = Clock::now();
    engine->Step();
    const double step_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    total_ms += step_ms;
    if (step + 1 == window_steps) result.window_step_ms = total_ms / window_steps;
    const StageTimes stages = engine->LastStageTimes();
    result.broad_phase_ms += stages.broad_phase_ms;
    result.narrow_phase_ms += stages.narrow_phase_ms;
    result.solver_ms += stages.solver_ms;
    result.integrator_ms += stages.integrator_ms;
    if (stages.solver_points > 0) {
      result.solver_point_iterations += static_cast<double>(stages.point_iterations);
      result.solver_rows_ms += stages.solver_ms;
      ++result.contact_steps;
      result.contact_steps_ms += step_ms;
      if (step < window_steps) {
        ++result.window_contact_steps;
        result.window_contact_ms += step_ms;
      }
    }
    result.peak_penetration = std::max(result.peak_penetration, engine->MaxPenetration());
    if (scene.kind == SceneKind::kTerrain) {
      for (int i = 0; i < static_cast<int>(scene.bodies.size()); ++i) {
        if (engine->LinearVelocity(i).norm() > 0.05) {
          last_moving_step = step;
          break;
        }
      }
    }
    if (scene.kind == SceneKind::kBounce && !apex_found) {
      // The first apex: the highest point between leaving the ground and
      // falling again.
      const double vz = engine->LinearVelocity(top).z();
      const double z = engine->Position(top).z();
      if (vz < -0.1) fell = true;
      if (fell && vz > 0.0) rose = true;
      if (rose) {
        highest = std::max(highest, z);
        if (vz <= 0.0) apex_found = true;
      }
    }
  }
  const double steps = result.steps;
  result.step_ms = total_ms / steps;
  result.broad_phase_ms /= steps;
  result.narrow_phase_ms /= steps;
  result.solver_ms /= steps;
  result.integrator_ms /= steps;
  result.final_kinetic_energy = engine->KineticEnergy();
  result.final_penetration = engine->MaxPenetration();
  const Vec3 top_end = engine->Position(top);
  switch (scene.kind) {
    case SceneKind::kPile:
      result.drift = (top_end - top_start).head<2>().norm();
      break;
    case SceneKind::kPyramid:
      result.drift = (top_end - top_start).norm();
      break;
    case SceneKind::kBounce:
      result.apex = apex_found ? highest - scene.bodies[0].sphere_radius : 0.0;
      break;
    case SceneKind::kIncline: {
      const Vec3 downhill = scene.world_from_ground.rotation * Vec3::UnitX();
      result.slide = (top_end - top_start).dot(downhill);
      break;
    }
    case SceneKind::kTerrain:
      result.settle_time = (last_moving_step + 1) * kTimeStep;
      for (int i = 0; i < static_cast<int>(scene.bodies.size()); ++i) {
        const Vec3 position = engine->Position(i);
        result.below_surface += position.z() < scene.hills.HeightAt(position.x(), position.y());
      }
      break;
  }
  result.ok = true;
  return result;
}

// Runs one scene in a child process; returns false when the child failed.
bool RunInChild(const Scene& scene, bool bullet, const RunSettings& settings, RunResult* result) {
  int fds[2];
  if (pipe(fds) != 0) return false;
  std::fflush(stdout);
  const pid_t pid = fork();
  if (pid < 0) return false;
  if (pid == 0) {
    close(fds[0]);
    const RunResult child_result = RunScene(scene, bullet, settings);
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
// defined; run k > 0 moves every body by up to kJitter (uniform per axis,
// seed k, the same for both engines), and the drift reported is the median
// over the runs.
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
Summary Summarize(const Scene& scene, bool bullet, std::vector<RunResult> results) {
  Summary summary;
  summary.scene = scene.name;
  summary.engine = bullet ? "bullet" : "ours";
  summary.bodies = static_cast<int>(scene.bodies.size());
  summary.seconds = scene.seconds;
  if (results.empty()) return summary;
  // Each quality figure is the median over the runs on its own, so that it
  // does not depend on which run the machine happened to run fastest; the
  // times and the stage profile are those of the median run by time.
  constexpr double RunResult::*kQualityFigures[] = {&RunResult::final_kinetic_energy,
                                                    &RunResult::final_penetration,
                                                    &RunResult::peak_penetration,
                                                    &RunResult::drift,
                                                    &RunResult::apex,
                                                    &RunResult::slide,
                                                    &RunResult::settle_time,
                                                    &RunResult::below_surface};
  std::vector<double> medians;
  for (double RunResult::*figure : kQualityFigures) {
    std::vector<double> values;
    for (const RunResult& result : results) values.push_back(result.*figure);
    medians.push_back(Median(std::move(values)));
  }
  std::sort(results.begin(), results.end(),
            [](const RunResult& a, const RunResult& b) { return a.step_ms < b.step_ms; });
  summary.median = results[results.size() / 2];
  for (std::size_t k = 0; k < medians.size(); ++k) {
    summary.median.*kQualityFigures[k] = medians[k];
  }
  summary.ms_median = summary.median.step_ms;
  summary.ms_min = results.front().step_ms;
  summary.ms_max = results.back().step_ms;
  for (const RunResult& result : results) {
    summary.peak_rss_kb = std::max(summary.peak_rss_kb, result.peak_rss_kb);
  }
  return summary;
}

// Runs a scene in both engines, run k of ours right before run k of Bullet
// (the same jitter seed), so that a change in the shared machine's load
// between runs reaches both engines alike. The ratio is the median over the
// runs of each pair's ours/Bullet ms per step.
std::pair<Summary, Summary> MeasureBoth(const Scene& scene, int runs, const RunSettings& settings) {
  std::vector<RunResult> ours_results;
  std::vector<RunResult> bullet_results;
  std::vector<double> ratios;
  for (int run = 0; run < runs; ++run) {
    const Scene jittered = JitterScene(scene, run);
    RunResult ours;
    RunResult bullet;
    const bool ours_ok = RunInChild(jittered, false, settings, &ours);
    const bool bullet_ok = RunInChild(jittered, true, settings, &bullet);
    if (!ours_ok) std::fprintf(stderr, "%s/ours: run %d failed\n", scene.name.c_str(), run);
    if (!bullet_ok) std::fprintf(stderr, "%s/bullet: run %d failed\n", scene.name.c_str(), run);
    if (ours_ok) ours_results.push_back(ours);
    if (bullet_ok) bullet_results.push_back(bullet);
    if (ours_ok && bullet_ok && bullet.step_ms > 0.0) {
      ratios.push_back(ours.step_ms / bullet.step_ms);
    }
  }
  std::pair<Summary, Summary> summaries(Summarize(scene, false, std::move(ours_results)),
                                        Summarize(scene, true, std::move(bullet_results)));
  summaries.first.ratio_to_bullet = Median(std::move(ratios));
  return summaries;
}

// The scene's quality figure as text and as a number for the CSV.
struct Quality {
  std::string text;
  double value = 0.0;  // bounce: relative apex error; incline: relative slide error or slide (m)
};

Quality SceneQuality(const Scene& scene, const RunResult& result) {
  char text[160];
  Quality quality;
  if (scene.kind == SceneKind::kBounce) {
    const double e = scene.bodies[0].material.restitution;
    const double expected = e * e * scene.drop_height;
    quality.value = (result.apex - expected) / expected;
    std::snprintf(text, sizeof(text), "apex %.4f m vs e^2h %.4f m: %+.1f %%", result.apex, expected,
                  100.0 * quality.value);
  } else if (scene.kind == SceneKind::kIncline) {
    const double theta = scene.slope_degrees * kPi / 180.0;
    const double mu = std::sqrt(scene.bodies[0].material.friction * scene.ground_material.friction);
    const double acceleration = kGravity * (std::sin(theta) - mu * std::cos(theta));
    const double expected =
        acceleration > 0.0 ? 0.5 * acceleration * scene.seconds * scene.seconds : 0.0;
    // Sliding when it moved more than 1 mm in 2 s.
    const bool slid = result.slide > 1e-3;
    const bool correct = slid == (expected > 0.0);
    if (expected > 0.0) {
      quality.value = (result.slide - expected) / expected;
      std::snprintf(text, sizeof(text), "slid %.4f m vs %.4f m: %+.2f %% (%s)", result.slide,
                    expected, 100.0 * quality.value, correct ? "slides, right" : "WRONG: sticks");
    } else {
      quality.value = result.slide;
      std::snprintf(text, sizeof(text), "slid %.2f mm, expected 0 (%s)", 1e3 * result.slide,
                    correct ? "sticks, right" : "WRONG: slides");
    }
  } else if (scene.kind == SceneKind::kTerrain) {
    std::snprintf(text, sizeof(text), "all at rest after %.2f s, %d below the surface",
                  result.settle_time, static_cast<int>(result.below_surface));
    quality.value = result.settle_time;
  } else {
    std::snprintf(text, sizeof(text), "top-box drift %.4f m", result.drift);
    quality.value = result.drift;
  }
  quality.text = text;
  return quality;
}

// The scenes that dominate the run time get fewer runs and less simulated
// time (Options).
bool IsLarge(const Scene& scene) { return scene.bodies.size() >= 4000; }

struct Options {
  std::string csv_path = "bench/results/latest.csv";
  int runs = 3;
  int large_runs = 1;  // runs of the scenes of 4,000 bodies and more
  double scale = 1.0;
  std::vector<std::string> only;
  std::string hull_bench;
  OurSettingsOverrides overrides;
  std::string error;  // set when an option's value is refused
};

Options ParseOptions(int argc, char** argv) {
  Options options;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const std::string value = argv[i + 1];
    if (key == "--csv") {
      options.csv_path = value;
    } else if (key == "--runs") {
      options.runs = std::max(1, std::atoi(value.c_str()));
    } else if (key == "--large-runs") {
      options.large_runs = std::max(1, std::atoi(value.c_str()));
    } else if (key == "--scale") {
      options.scale = std::atof(value.c_str());
    } else if (key == "--only") {
      std::stringstream list(value);
      std::string name;
      while (std::getline(list, name, ',')) options.only.push_back(name);
    } else if (key == "--hull-bench") {
      options.hull_bench = value;
    } else if (key == "--velocity-iterations") {
      char* end = nullptr;
      const long iterations = std::strtol(value.c_str(), &end, 10);
      if (*end != '\0' || iterations < 1 || iterations > 10000) {
        options.error = "--velocity-iterations wants a whole number in [1, 10000], got " + value;
      } else {
        options.overrides.velocity_iterations = static_cast<int>(iterations);
      }
    } else if (key == "--time-to-sleep") {
      char* end = nullptr;
      const double seconds = std::strtod(value.c_str(), &end);
      if (*end != '\0' || !(seconds > 0.0) || !std::isfinite(seconds)) {
        options.error = "--time-to-sleep wants a time in s, > 0, got " + value;
      } else {
        options.overrides.time_to_sleep = seconds;
      }
    } else if (key == "--velocity-tolerance") {
      char* end = nullptr;
      const double tolerance = std::strtod(value.c_str(), &end);
      if (*end != '\0' || !(tolerance >= 0.0) || !std::isfinite(tolerance)) {
        options.error = "--velocity-tolerance wants a speed in m/s, >= 0, got " + value;
      } else {
        options.overrides.velocity_tolerance = tolerance;
      }
    } else if (key == "--interleave-independent-runs") {
      if (value != "0" && value != "1") {
        options.error = "--interleave-independent-runs wants 0 or 1, got " + value;
      } else {
        options.overrides.interleave_independent_runs = value == "1";
      }
    } else {
      std::fprintf(stderr, "unknown option %s\n", key.c_str());
    }
  }
  return options;
}

std::string RunCommand(const std::string& command) {
  std::string output;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return output;
  char buffer[512];
  while (std::fgets(buffer, sizeof(buffer), pipe) != nullptr) output += buffer;
  pclose(pipe);
  return output;
}

// ns per contact row per solver iteration.
double RowCostNs(const RunResult& result) {
  const double rows = result.solver_point_iterations * result.rows_per_point;
  return rows > 0.0 ? 1e6 * result.solver_rows_ms / rows : 0.0;
}

// The scenes of the run: every scene, or the ones --only names. Simulated
// seconds: 10 s, except the two largest scenes, which --scale shortens.
std::vector<Scene> SelectScenes(const Options& options) {
  std::vector<Scene> scenes = {
      MakePile(100, 10.0),
      MakePile(1000, 10.0),
      MakePile(4000, 10.0 * options.scale),
      MakePyramid(20, 10.0),
      MakePyramid(40, 10.0),
      MakePyramid(90, 10.0 * options.scale),
      MakeBounce(),
      MakeIncline(20.0),
      MakeIncline(25.0),
      MakeIncline(28.0),
      MakeIncline(35.0),
      MakeTerrain(100, 100000, 10.0),
      MakeFlatTerrain(100, 10.0),
  };
  if (!options.only.empty()) {
    scenes.erase(std::remove_if(scenes.begin(), scenes.end(),
                                [&](const Scene& scene) {
                                  return std::find(options.only.begin(), options.only.end(),
                                                   scene.name) == options.only.end();
                                }),
                 scenes.end());
  }

  return scenes;
}

void PrintHeader(const Options& options, double window_seconds) {
  if (options.scale != 1.0 || options.large_runs != options.runs) {
    std::printf(
        "scenes of 4,000 bodies and more: %.2f s of simulated time instead of 10 s, "
        "%d run(s)\n\n",
        window_seconds, options.large_runs);
  }
  const OurSettingsOverrides& overrides = options.overrides;
  if (overrides.velocity_iterations) {
    std::printf("ours: velocity_iterations = %d instead of the default\n",
                *overrides.velocity_iterations);
  }
  if (overrides.time_to_sleep) {
    std::printf("ours: time_to_sleep = %g s instead of the default\n", *overrides.time_to_sleep);
  }
  if (overrides.velocity_tolerance) {
    std::printf("ours: velocity_tolerance = %g m/s instead of the default\n",
                *overrides.velocity_tolerance);
  }
  if (overrides.interleave_independent_runs) {
    std::printf("ours: interleave_independent_runs = %s\n",
                *overrides.interleave_independent_runs ? "true" : "false");
  }
  std::printf(
      "dt = 1/240 s, one step per output frame; wall ms per step: median of %d runs "
      "[min, max], each run in its own process, run k of ours right before run k of Bullet; "
      "ours/blt: the median of the runs' ratios\n",
      options.runs);
  std::printf(
      "quality figures (KE, pen, drift, apex, slide): each the median over the runs (run 0 as "
      "defined, run k > 0 with every body moved by up to 1 um, seed k, the same for both "
      "engines); drift: pile = horizontal distance of the top box from its column, pyramid = "
      "distance of the top box from its start; pen = deepest contact at the end [peak over "
      "the run]\n\n");
  std::printf("%-11s %-6s %6s %6s %23s %9s %9s %10s %11s %15s %7s  %s\n", "scene", "engine",
              "bodies", "sim s", "ms/step med [min, max]", "steps/s", "ours/blt", "KE J", "pen mm",
              "peak pen mm", "RSS MB", "quality");
}

using Rows = std::vector<std::pair<Summary, Summary>>;  // (ours, bullet) per scene

// Runs every scene in both engines and prints a row each.
Rows MeasureScenes(const Options& options, const std::vector<Scene>& scenes,
                   double window_seconds) {
  std::vector<std::pair<Summary, Summary>> rows;  // (ours, bullet) per scene
  for (const Scene& scene : scenes) {
    const int runs = IsLarge(scene) ? options.large_runs : options.runs;
    const RunSettings run_settings{window_seconds, options.overrides};
    const auto [ours, bullet] = MeasureBoth(scene, runs, run_settings);
    for (const Summary* summary : {&ours, &bullet}) {
      const Quality quality = SceneQuality(scene, summary->median);
      char ratio[32] = "";
      if (summary == &ours && ours.ratio_to_bullet > 0.0) {
        std::snprintf(ratio, sizeof(ratio), "%.2f", ours.ratio_to_bullet);
      }
      std::printf(
          "%-11s %-6s %6d %6.2f %8.3f [%6.3f,%6.3f] %9.0f %9s %10.3g %11.2f %15.2f %7.1f  %s\n",
          scene.name.c_str(), summary->engine.c_str(), summary->bodies, summary->seconds,
          summary->ms_median, summary->ms_min, summary->ms_max, 1e3 / summary->ms_median, ratio,
          summary->median.final_kinetic_energy, 1e3 * summary->median.final_penetration,
          1e3 * summary->median.peak_penetration, summary->peak_rss_kb / 1024.0,
          quality.text.c_str());
    }
    std::fflush(stdout);
    rows.emplace_back(ours, bullet);
  }

  return rows;
}

// Stage profile and the cost of one contact row in one solver iteration.
void PrintStageProfile(const Rows& rows) {
  std::printf(
      "\nstage profile, ms per step (mean of the median run); solver ns per row-iteration "
      "= solver time of the steps with contacts / (point updates of the velocity iterations x "
      "rows per point); ours: each island's points times the sweeps it ran (up to 20), 3 rows "
      "per point (normal + 2-D friction), and its solver stage also holds the collision rounds "
      "and 6 position sweeps; Bullet: points x 10 iterations, 2 rows per point; contact s = "
      "simulated time of the steps with contact points to "
      "solve (the rest is free flight or asleep), ms/contact step = wall time of one of them\n");
  std::printf("%-11s %-6s %9s %9s %9s %9s %13s %10s %16s\n", "scene", "engine", "broad", "narrow",
              "solver", "integr", "ns/row-iter", "contact s", "ms/contact step");
  for (const auto& [ours, bullet] : rows) {
    for (const Summary* summary : {&ours, &bullet}) {
      const RunResult& result = summary->median;
      std::printf("%-11s %-6s %9.3f %9.3f %9.3f %9.3f %13.1f %10.2f %16.3f\n",
                  summary->scene.c_str(), summary->engine.c_str(), result.broad_phase_ms,
                  result.narrow_phase_ms, result.solver_ms, result.integrator_ms, RowCostNs(result),
                  result.contact_steps * kTimeStep, ContactStepMs(result));
    }
  }
}

// Scaling from pile_1000 to pile_4000.
void PrintScaling(const Rows& rows, double window_seconds) {
  const Summary* pile_1000[2] = {nullptr, nullptr};
  const Summary* pile_4000[2] = {nullptr, nullptr};
  for (const auto& row : rows) {
    if (row.first.scene == "pile_1000") pile_1000[0] = &row.first, pile_1000[1] = &row.second;
    if (row.first.scene == "pile_4000") pile_4000[0] = &row.first, pile_4000[1] = &row.second;
  }
  // Over the same window of simulated time from the drop, so that both
  // piles are in the same phase (falling, landing) when compared.
  if (pile_1000[0] != nullptr && pile_4000[0] != nullptr) {
    std::printf(
        "\nscaling pile_1000 -> pile_4000, ms/step over the first %.2f s of each "
        "(4 x the bodies; 4.0 is linear):",
        window_seconds);
    for (int e = 0; e < 2; ++e) {
      std::printf(" %s %.3f -> %.3f ms, x%.2f;", e == 0 ? "ours" : "bullet",
                  pile_1000[e]->median.window_step_ms, pile_4000[e]->median.window_step_ms,
                  pile_4000[e]->median.window_step_ms / pile_1000[e]->median.window_step_ms);
    }
    // The same per step with contacts to solve: the larger pile takes longer
    // to settle, and an engine that puts the smaller one to sleep within the
    // window sees its ms/step ratio grow by that alone.
    std::printf("\n  per step with contact points in that window:");
    for (int e = 0; e < 2; ++e) {
      auto per_step = [](const RunResult& result) {
        return result.window_contact_steps > 0
                   ? result.window_contact_ms / result.window_contact_steps
                   : 0.0;
      };
      const double small = per_step(pile_1000[e]->median);
      const double large = per_step(pile_4000[e]->median);
      std::printf(" %s %.3f -> %.3f ms, x%.2f (%.2f -> %.2f s with contacts);",
                  e == 0 ? "ours" : "bullet", small, large, small > 0.0 ? large / small : 0.0,
                  pile_1000[e]->median.window_contact_steps * kTimeStep,
                  pile_4000[e]->median.window_contact_steps * kTimeStep);
    }
    std::printf("\n");
  }
}

void WriteCsv(const std::vector<Scene>& scenes, const Rows& rows, std::ofstream& csv) {
  csv << "scene,engine,bodies,sim_seconds,steps,ms_per_step_median,ms_per_step_min,"
         "ms_per_step_max,steps_per_second,ratio_ours_over_bullet,final_kinetic_energy_j,"
         "final_penetration_m,peak_penetration_m,top_box_drift_m,bounce_apex_m,"
         "bounce_apex_error,incline_slide_m,incline_error,broad_phase_ms,narrow_phase_ms,"
         "solver_ms,integrator_ms,solver_ns_per_row_iteration,peak_rss_kb,contact_seconds,"
         "ms_per_contact_step,terrain_settle_s,terrain_below_surface\n";
  std::map<std::string, const Scene*> scene_by_name;
  for (const Scene& scene : scenes) scene_by_name[scene.name] = &scene;
  for (const auto& [ours, bullet] : rows) {
    for (const Summary* summary : {&ours, &bullet}) {
      const Scene& scene = *scene_by_name[summary->scene];
      const RunResult& result = summary->median;
      const Quality quality = SceneQuality(scene, result);
      const double ratio = summary == &ours ? ours.ratio_to_bullet : 0.0;
      csv << summary->scene << ',' << summary->engine << ',' << summary->bodies << ','
          << summary->seconds << ',' << result.steps << ',' << summary->ms_median << ','
          << summary->ms_min << ',' << summary->ms_max << ',' << 1e3 / summary->ms_median << ','
          << (summary == &ours ? std::to_string(ratio) : std::string()) << ','
          << result.final_kinetic_energy << ',' << result.final_penetration << ','
          << result.peak_penetration << ','
          << (scene.kind == SceneKind::kPile || scene.kind == SceneKind::kPyramid
                  ? std::to_string(result.drift)
                  : std::string())
          << ',' << (scene.kind == SceneKind::kBounce ? std::to_string(result.apex) : "") << ','
          << (scene.kind == SceneKind::kBounce ? std::to_string(quality.value) : "") << ','
          << (scene.kind == SceneKind::kIncline ? std::to_string(result.slide) : "") << ','
          << (scene.kind == SceneKind::kIncline ? std::to_string(quality.value) : "") << ','
          << result.broad_phase_ms << ',' << result.narrow_phase_ms << ',' << result.solver_ms
          << ',' << result.integrator_ms << ',' << RowCostNs(result) << ',' << summary->peak_rss_kb
          << ',' << result.contact_steps * kTimeStep << ',' << ContactStepMs(result) << ','
          << (scene.kind == SceneKind::kTerrain ? std::to_string(result.settle_time) : "") << ','
          << (scene.kind == SceneKind::kTerrain ? std::to_string(result.below_surface) : "")
          << '\n';
    }
  }
}

// Runs the hull benchmark and adds its row to the CSV.
void RunHullBench(const std::string& hull_bench, std::ofstream& csv) {
  std::printf("\nhull: %s (our io library; Bullet has no mesh-to-hull pipeline to compare)\n",
              hull_bench.c_str());
  const std::string output = RunCommand(hull_bench);
  std::printf("%s", output.c_str());
  double load_ms = 0.0, hull_ms = 0.0, total_ms = 0.0;
  const std::size_t at = output.find("best of");
  if (at != std::string::npos &&
      std::sscanf(output.c_str() + at, "best of %*d: load %lf ms, hull %lf ms, total %lf ms",
                  &load_ms, &hull_ms, &total_ms) == 3) {
    // Load and hull of one mesh: the "step" is the whole task (best of the
    // program's repetitions, so min = median = max).
    csv << "hull,ours,1,,1," << total_ms << ',' << total_ms << ',' << total_ms
        << std::string(18, ',') << '\n';
  }
}

int Main(int argc, char** argv) {
  const Options options = ParseOptions(argc, argv);
  if (!options.error.empty()) {
    std::fprintf(stderr, "physics_bench: %s\n", options.error.c_str());
    return 2;
  }
  const std::vector<Scene> scenes = SelectScenes(options);
  const double window_seconds = 10.0 * options.scale;
  PrintHeader(options, window_seconds);
  const Rows rows = MeasureScenes(options, scenes, window_seconds);
  PrintStageProfile(rows);
  PrintScaling(rows, window_seconds);
  std::ofstream csv(options.csv_path);
  WriteCsv(scenes, rows, csv);
  if (!options.hull_bench.empty()) RunHullBench(options.hull_bench, csv);
  std::printf("\nwrote %s\n", options.csv_path.c_str());
  return 0;
}

}  // namespace
}  // namespace rigid_body_sim::bench

int main(int argc, char** argv) { return rigid_body_sim::bench::Main(argc, argv); }
