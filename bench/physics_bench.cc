// Runs the benchmark scenes (scene.h) in our engine (with the exact solver
// and with the soft step, each on one and on two threads), in Bullet with its
// defaults and in Bullet with our sleep thresholds, and prints per scene and
// engine the wall time per step (median of the runs, with min and max), the
// time per step with every moving body awake, the ratios of ours to each
// Bullet, the quality figures, the time per stage, the cost per contact row
// per solver iteration and the peak memory. Writes the rows to a CSV file.
//
// Each run is a child process (fork), so its peak resident memory is its
// own (wait4's ru_maxrss) and no run inherits another's allocator state.
// The engines' runs alternate, and each ratio is the median of the ratios of
// runs made back to back, as the machines are shared and their load drifts
// over minutes (measure.h).
//
// Usage: physics_bench [--csv PATH] [--runs N] [--large-runs N] [--scale S]
//                      [--only a,b]
//                      [--hull-bench PATH]
//                      [--velocity-iterations N] [--time-to-sleep S]
//                      [--velocity-tolerance V] [--interleave-independent-runs 0|1]
//                      [--batch-independent-runs 0|1] [--soft-simd-lanes 0|1]
//                      [--hill-amplitude A]
//                      [--articulated-rates 240,1000]
//   --scale S multiplies the simulated time of pile_4000 and pyramid_90,
//   the two scenes that dominate the run time, and --large-runs N sets
//   their number of runs. --velocity-iterations, --time-to-sleep (s),
//   --velocity-tolerance (m/s), --interleave-independent-runs,
//   --batch-independent-runs and --soft-simd-lanes (the soft step's) run our
//   engine with those solver and sleep settings instead of the defaults, to
//   measure what a setting costs or buys; the header says so
//   (--time-to-sleep also reaches bullet_oursleep). --hill-amplitude A (m,
//   [0, 2], default 0.5) sets the height of terrain_100's hills, to measure
//   how the time to rest grows with their slope. --articulated-rates lists
//   the step rates (Hz, default 240 and 1000) at which each articulated
//   scene runs; the free-body scenes always step at 240 Hz. A row at another
//   rate than 240 Hz has "_<rate>hz" after its scene's name.
//
// The articulated scenes (chain_30, arm_push_100, panda_like, panda_held,
// ur5_like) also run in MuJoCo with its RK4 and with its Euler integrator,
// and each of their rows gives the engine's energy drift, or the servo
// error of its motors, beside its time; a run whose energy grew by more
// than 10 % of the scene's scale or turned non-finite is marked diverged
// and gives no ratio (measure.h).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "engine.h"
#include "measure.h"
#include "report.h"
#include "scene.h"

namespace rigid_body_sim::bench {
namespace {

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
  double hill_amplitude = 0.5;                       // m, terrain_100's hills
  std::vector<int> articulated_rates = {240, 1000};  // Hz
  OurSettingsOverrides overrides;
  std::string error;  // set when an option's value is refused
};

// A finite number that is the whole of `text`, or nothing.
std::optional<double> ParseNumber(const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(value)) return std::nullopt;
  return value;
}

// "0" or "1" as a flag, or nothing.
std::optional<bool> ParseFlag(const std::string& text) {
  if (text == "0" || text == "1") return text == "1";
  return std::nullopt;
}

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
    } else if (key == "--articulated-rates") {
      options.articulated_rates.clear();
      std::stringstream list(value);
      std::string rate;
      while (std::getline(list, rate, ',')) {
        const std::optional<double> hz = ParseNumber(rate);
        if (!hz || *hz < 1.0 || *hz > 100000.0 || *hz != std::floor(*hz)) {
          options.error = "--articulated-rates wants whole step rates in Hz, got " + value;
        } else {
          options.articulated_rates.push_back(static_cast<int>(*hz));
        }
      }
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
      const std::optional<double> seconds = ParseNumber(value);
      if (!seconds || !(*seconds > 0.0)) {
        options.error = "--time-to-sleep wants a time in s, > 0, got " + value;
      } else {
        options.overrides.time_to_sleep = *seconds;
      }
    } else if (key == "--velocity-tolerance") {
      const std::optional<double> tolerance = ParseNumber(value);
      if (!tolerance || !(*tolerance >= 0.0)) {
        options.error = "--velocity-tolerance wants a speed in m/s, >= 0, got " + value;
      } else {
        options.overrides.velocity_tolerance = *tolerance;
      }
    } else if (key == "--hill-amplitude") {
      const std::optional<double> amplitude = ParseNumber(value);
      if (!amplitude || !(*amplitude >= 0.0 && *amplitude <= 2.0)) {
        options.error = "--hill-amplitude wants a height in m in [0, 2], got " + value;
      } else {
        options.hill_amplitude = *amplitude;
      }
    } else if (key == "--interleave-independent-runs" || key == "--batch-independent-runs" ||
               key == "--soft-simd-lanes") {
      const std::optional<bool> flag = ParseFlag(value);
      if (!flag) {
        options.error = key + " wants 0 or 1, got " + value;
      } else if (key == "--interleave-independent-runs") {
        options.overrides.interleave_independent_runs = *flag;
      } else if (key == "--batch-independent-runs") {
        options.overrides.batch_independent_runs = *flag;
      } else {
        options.overrides.soft_simd_lanes = *flag;
      }
    } else {
      std::fprintf(stderr, "unknown option %s\n", key.c_str());
    }
  }
  return options;
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
      MakeTerrain(100, 100000, 10.0, options.hill_amplitude),
      MakeFlatTerrain(100, 10.0),
  };
  const std::vector<Scene> articulated = {MakeChain(30, 10.0), MakeArmPush(100, 10.0),
                                          MakePandaLike(false, 5.0), MakePandaLike(true, 5.0),
                                          MakeUr5Like(5.0)};
  for (const Scene& scene : articulated) {
    for (const int hz : options.articulated_rates) scenes.push_back(AtStepRate(scene, hz));
  }
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
  if (overrides.batch_independent_runs) {
    std::printf("ours: batch_independent_runs = %s\n",
                *overrides.batch_independent_runs ? "true" : "false");
  }
  if (overrides.soft_simd_lanes) {
    std::printf("ours, soft step: simd_lanes = %s\n",
                *overrides.soft_simd_lanes ? "true" : "false");
  }
  if (options.hill_amplitude != 0.5) {
    std::printf("terrain_100: hills of %g m instead of 0.5 m\n", options.hill_amplitude);
  }
  std::printf(
      "dt = 1/240 s (articulated rows at another rate: 1/rate, named _<rate>hz), one step per "
      "output frame; wall ms per step: median of %d runs "
      "[min, max], each run in its own process, run k of each engine right after another; "
      "awake ms: ms per step over the steps with every moving body awake (median over the "
      "runs); ours/it, awake: ours over that engine, ms per step and ms per awake step, the "
      "median of the runs' ratios; bullet_oursleep: Bullet with our sleep thresholds and time; "
      "ours x2: ours on two threads (its ours/it: ours on one thread over it); "
      "ours soft_step: ours with the soft step (WorldSettings::motion_solver = kSoftStep) "
      "instead of the exact solver, on one thread and (x2) on two; soft aw, soft2 aw: the soft "
      "step on one and on two threads over that engine, ms per awake step; "
      "articulated scenes: Bullet's btMultiBody, and MuJoCo with RK4 and with Euler\n",
      options.runs);
  std::printf(
      "quality figures (KE, pen, drift, apex, slide): each the median over the runs (run 0 as "
      "defined, run k > 0 with every body moved by up to 1 um, seed k, the same for both "
      "engines); drift: pile = horizontal distance of the top box from its column, pyramid = "
      "distance of the top box from its start; pen = deepest contact at the end [peak over "
      "the run]; articulated rows: energy drift = (E_end - E_0) / scale [largest growth "
      "(E - E_0) / scale over the run], E = kinetic + m g z over the moving bodies, scale = sum "
      "m g |c - base| at the start; servo = largest distance of a motored joint from its "
      "commanded angle; DIVERGED: the energy grew by more than 10 %% of the scale or turned "
      "non-finite (in that many runs); such runs give no ratio\n\n");
  PrintTableHeader();
}

// Runs every scene in every engine and prints its rows.
Rows MeasureScenes(const Options& options, const std::vector<Scene>& scenes,
                   double window_seconds) {
  // Ours first (PrintScaling reads the first two rows as ours and Bullet);
  // the soft step runs every scene too, the articulated ones included, where
  // it changes only the solve of the contacts without a link.
  const std::vector<EngineKind> engines = {
      EngineKind::kOurs,           EngineKind::kBullet,   EngineKind::kBulletOurSleep,
      EngineKind::kOursTwoThreads, EngineKind::kOursSoft, EngineKind::kOursSoftTwoThreads};
  std::vector<EngineKind> articulated_engines = engines;
  articulated_engines.push_back(EngineKind::kMujocoRk4);
  articulated_engines.push_back(EngineKind::kMujocoEuler);
  Rows rows;
  for (const Scene& scene : scenes) {
    const int runs = IsLarge(scene) ? options.large_runs : options.runs;
    const RunSettings run_settings{window_seconds, options.overrides};
    rows.push_back(MeasureEngines(scene, runs, run_settings,
                                  scene.articulations.empty() ? engines : articulated_engines));
    PrintSceneRows(scene, rows.back());
  }
  return rows;
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
