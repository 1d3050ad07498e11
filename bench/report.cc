#include "report.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <utility>

namespace rigid_body_sim::bench {
namespace {

// The scene's quality figure as text and as a number for the CSV.
struct Quality {
  std::string text;
  double value = 0.0;  // bounce: relative apex error; incline: relative slide error or slide (m)
};

Quality InclineQuality(const Scene& scene, const RunResult& result) {
  char text[160];
  Quality quality;
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
  quality.text = text;
  return quality;
}

Quality SceneQuality(const Scene& scene, const RunResult& result) {
  char text[160];
  Quality quality;
  switch (scene.kind) {
    case SceneKind::kIncline:
      return InclineQuality(scene, result);
    case SceneKind::kBounce: {
      const double e = scene.bodies[0].material.restitution;
      const double expected = e * e * scene.drop_height;
      quality.value = (result.apex - expected) / expected;
      std::snprintf(text, sizeof(text), "apex %.4f m vs e^2h %.4f m: %+.1f %%", result.apex,
                    expected, 100.0 * quality.value);
      break;
    }
    case SceneKind::kChain:
      quality.value = result.joint_separation;
      std::snprintf(text, sizeof(text), "largest joint anchor separation %.3g m",
                    result.joint_separation);
      break;
    case SceneKind::kArmPush:
      quality.value = result.driven_swept;
      std::snprintf(text, sizeof(text),
                    "%.0f boxes moved; yaw swept %.2f of %.2f rad commanded; joint sep. %.2g m",
                    result.boxes_moved, result.driven_swept, result.driven_commanded,
                    result.joint_separation);
      break;
    case SceneKind::kTerrain:
      quality.value = result.settle_time;
      std::snprintf(text, sizeof(text), "all at rest after %.2f s, %.0f below the surface",
                    result.settle_time, result.below_surface);
      break;
    case SceneKind::kLimpArm:
      quality.value = result.energy_drift;
      std::snprintf(text, sizeof(text), "joint sep. %.2g m", result.joint_separation);
      break;
    case SceneKind::kHeldArm:
      quality.value = result.servo_error;
      std::snprintf(text, sizeof(text), "joint sep. %.2g m", result.joint_separation);
      break;
    default:
      quality.value = result.drift;
      std::snprintf(text, sizeof(text), "top-box drift %.4f m", result.drift);
  }
  quality.text = text;
  return quality;
}

// An articulated row's energy drift and growth (as percentages of the
// scene's energy scale), its servo error where it has motors, and the mark
// of runs that diverged; empty for the other scenes.
std::string ArticulatedFigures(const Scene& scene, const Summary& summary) {
  if (scene.articulations.empty()) return "";
  const RunResult& result = summary.median;
  char text[160];
  std::snprintf(text, sizeof(text), "; E drift %+.3g %% [growth %.3g %%]",
                100.0 * result.energy_drift, 100.0 * result.energy_growth);
  std::string figures = text;
  bool motors = false;
  for (const BenchArticulation& articulation : scene.articulations) {
    for (const std::vector<MotorPhase>& motor : articulation.motors) motors |= !motor.empty();
  }
  if (motors) {
    std::snprintf(text, sizeof(text), "; servo %.3g rad", result.servo_error);
    figures += text;
  }
  if (summary.diverged_runs > 0) {
    figures += "; DIVERGED (" + std::to_string(summary.diverged_runs) + " runs)";
  }
  return figures;
}

std::string Number(double value) {
  std::ostringstream out;
  out.precision(9);
  out << value;
  return out.str();
}

// One CSV line of the columns of CsvColumns; absent columns are empty.
void WriteCsvLine(const std::map<std::string, std::string>& values, std::ofstream& csv) {
  const std::vector<std::string>& columns = CsvColumns();
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const auto found = values.find(columns[c]);
    if (c > 0) csv << ',';
    if (found != values.end()) csv << found->second;
  }
  csv << '\n';
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

// The ratio columns of ours over a row that MeasureEngines measured; a
// ratio not measured (0) leaves its column empty.
void AddRatioValues(const Summary& summary, std::map<std::string, std::string>* values) {
  const std::pair<const char*, double> kRatios[] = {
      {"ours_over_this_ms_per_step", summary.ours_over_this},
      {"ours_over_this_ms_per_awake_step", summary.ours_over_this_awake},
      {"ours2_over_this_ms_per_step", summary.ours2_over_this},
      {"ours2_over_this_ms_per_awake_step", summary.ours2_over_this_awake},
      {"soft_over_this_ms_per_step", summary.soft_over_this},
      {"soft_over_this_ms_per_awake_step", summary.soft_over_this_awake},
      {"soft2_over_this_ms_per_step", summary.soft2_over_this},
      {"soft2_over_this_ms_per_awake_step", summary.soft2_over_this_awake}};
  for (const auto& [column, ratio] : kRatios) {
    if (ratio > 0.0) (*values)[column] = Number(ratio);
  }
}

std::string Ratio(double ratio) {
  if (ratio <= 0.0) return "";
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f", ratio);
  return text;
}

}  // namespace

void PrintTableHeader() {
  std::printf("%-12s %-17s %6s %6s %26s %9s %8s %8s %8s %8s %9s %9s %11s %7s  %s\n", "scene",
              "engine", "bodies", "sim s", "ms/step med [min, max]", "awake ms", "ours/it", "awake",
              "soft aw", "soft2 aw", "KE J", "pen mm", "peak pen mm", "RSS MB", "quality");
}

void PrintSceneRows(const Scene& scene, const std::vector<Summary>& summaries) {
  for (const Summary& summary : summaries) {
    const Quality quality = SceneQuality(scene, summary.median);
    std::printf(
        "%-12s %-17s %6d %6.2f %9.3f [%7.3f,%7.3f] %9.3f %8s %8s %8s %8s %9.3g %9.2f %11.2f %7.1f  "
        "%s\n",
        scene.name.c_str(), EngineLabel(summary).c_str(), summary.bodies, summary.seconds,
        summary.ms_median, summary.ms_min, summary.ms_max, summary.awake_ms_median,
        Ratio(summary.ours_over_this).c_str(), Ratio(summary.ours_over_this_awake).c_str(),
        Ratio(summary.soft_over_this_awake).c_str(), Ratio(summary.soft2_over_this_awake).c_str(),
        summary.median.final_kinetic_energy, 1e3 * summary.median.final_penetration,
        1e3 * summary.median.peak_penetration, summary.peak_rss_kb / 1024.0,
        (quality.text + ArticulatedFigures(scene, summary)).c_str());
  }
  std::fflush(stdout);
}

void PrintStageProfile(const Rows& rows) {
  std::printf(
      "\nstage profile, ms per step (mean of the median run); solver ns per row-iteration "
      "= solver time of the steps with contacts / (point updates of the velocity iterations x "
      "rows per point); ours: each island's points times the sweeps it ran (up to 20), 3 rows "
      "per point (normal + 2-D friction), and its solver stage also holds the collision rounds "
      "and 6 position sweeps; Bullet: points x 10 iterations, 2 rows per point; contact s = "
      "simulated time of the steps with contact points to solve (the rest is free flight or "
      "asleep), ms/contact step = wall time of one of them; awake s = simulated time with "
      "every moving body awake\n");
  std::printf("%-12s %-17s %9s %9s %9s %9s %13s %10s %16s %8s\n", "scene", "engine", "broad",
              "narrow", "solver", "integr", "ns/row-iter", "contact s", "ms/contact step",
              "awake s");
  for (const std::vector<Summary>& scene_rows : rows) {
    for (const Summary& summary : scene_rows) {
      const RunResult& result = summary.median;
      std::printf("%-12s %-17s %9.3f %9.3f %9.3f %9.3f %13.1f %10.2f %16.3f %8.2f\n",
                  summary.scene.c_str(), EngineLabel(summary).c_str(), result.broad_phase_ms,
                  result.narrow_phase_ms, result.solver_ms, result.integrator_ms, RowCostNs(result),
                  result.contact_steps * summary.time_step, ContactStepMs(result),
                  result.awake_steps * summary.time_step);
    }
  }
}

void PrintScaling(const Rows& rows, double window_seconds) {
  // Ours and Bullet (the first two engines) of each pile.
  const std::vector<Summary>* pile_1000 = nullptr;
  const std::vector<Summary>* pile_4000 = nullptr;
  for (const std::vector<Summary>& scene_rows : rows) {
    if (scene_rows.size() < 2) continue;
    if (scene_rows[0].scene == "pile_1000") pile_1000 = &scene_rows;
    if (scene_rows[0].scene == "pile_4000") pile_4000 = &scene_rows;
  }
  if (pile_1000 == nullptr || pile_4000 == nullptr) return;
  // Over the same window of simulated time from the drop, so that both
  // piles are in the same phase (falling, landing) when compared.
  std::printf(
      "\nscaling pile_1000 -> pile_4000, ms/step over the first %.2f s of each "
      "(4 x the bodies; 4.0 is linear):",
      window_seconds);
  for (int e = 0; e < 2; ++e) {
    const RunResult& small = (*pile_1000)[e].median;
    const RunResult& large = (*pile_4000)[e].median;
    std::printf(" %s %.3f -> %.3f ms, x%.2f;", (*pile_1000)[e].engine.c_str(), small.window_step_ms,
                large.window_step_ms, large.window_step_ms / small.window_step_ms);
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
    const RunResult& small = (*pile_1000)[e].median;
    const RunResult& large = (*pile_4000)[e].median;
    const double small_ms = per_step(small);
    const double large_ms = per_step(large);
    std::printf(" %s %.3f -> %.3f ms, x%.2f (%.2f -> %.2f s with contacts);",
                (*pile_1000)[e].engine.c_str(), small_ms, large_ms,
                small_ms > 0.0 ? large_ms / small_ms : 0.0,
                small.window_contact_steps * kDefaultTimeStep,
                large.window_contact_steps * kDefaultTimeStep);
  }
  std::printf("\n");
}

const std::vector<std::string>& CsvColumns() {
  static const std::vector<std::string> kColumns = {
      "scene", "engine", "threads", "solver", "steps", "ms_per_step_median",
      "ms_per_awake_step_median", "max_penetration_m", "top_drift_m",
      // The rest of the report.
      "bodies", "sim_seconds", "ms_per_step_min", "ms_per_step_max", "steps_per_second",
      "ours_over_this_ms_per_step", "ours_over_this_ms_per_awake_step",
      "ours2_over_this_ms_per_step", "ours2_over_this_ms_per_awake_step",
      "soft_over_this_ms_per_step", "soft_over_this_ms_per_awake_step",
      "soft2_over_this_ms_per_step", "soft2_over_this_ms_per_awake_step", "awake_seconds",
      "final_kinetic_energy_j", "final_penetration_m", "bounce_apex_m", "bounce_apex_error",
      "incline_slide_m", "incline_error", "joint_separation_m", "boxes_moved",
      "driven_joint_swept_rad", "driven_joint_commanded_rad", "broad_phase_ms", "narrow_phase_ms",
      "solver_ms", "integrator_ms", "solver_ns_per_row_iteration", "peak_rss_kb", "contact_seconds",
      "ms_per_contact_step", "time_step_s", "energy_drift", "energy_growth", "energy_start_j",
      "servo_error_rad", "diverged_runs"};
  return kColumns;
}

// The columns of the scene's own figures: drift, apex, slide, joints, the
// terrain's settling.
void AddSceneValues(const Scene& scene, const RunResult& result,
                    std::map<std::string, std::string>* values_out) {
  std::map<std::string, std::string>& values = *values_out;
  const Quality quality = SceneQuality(scene, result);
  switch (scene.kind) {
    case SceneKind::kPile:
    case SceneKind::kPyramid:
      values["top_drift_m"] = Number(result.drift);
      break;
    case SceneKind::kBounce:
      values["bounce_apex_m"] = Number(result.apex);
      values["bounce_apex_error"] = Number(quality.value);
      break;
    case SceneKind::kIncline:
      values["incline_slide_m"] = Number(result.slide);
      values["incline_error"] = Number(quality.value);
      break;
    case SceneKind::kLimpArm:
    case SceneKind::kHeldArm:
      values["joint_separation_m"] = Number(result.joint_separation);
      break;
    case SceneKind::kArmPush:
      values["boxes_moved"] = Number(result.boxes_moved);
      values["driven_joint_swept_rad"] = Number(result.driven_swept);
      values["driven_joint_commanded_rad"] = Number(result.driven_commanded);
      [[fallthrough]];
    case SceneKind::kChain:
      values["joint_separation_m"] = Number(result.joint_separation);
      break;
    case SceneKind::kTerrain:
      values["terrain_settle_s"] = Number(result.settle_time);
      values["terrain_below_surface"] = Number(result.below_surface);
      break;
  }
}

void WriteCsv(const std::vector<Scene>& scenes, const Rows& rows, std::ofstream& csv) {
  const std::vector<std::string>& columns = CsvColumns();
  for (std::size_t c = 0; c < columns.size(); ++c) csv << (c > 0 ? "," : "") << columns[c];
  csv << '\n';
  std::map<std::string, const Scene*> scene_by_name;
  for (const Scene& scene : scenes) scene_by_name[scene.name] = &scene;
  for (const std::vector<Summary>& scene_rows : rows) {
    for (const Summary& summary : scene_rows) {
      const Scene& scene = *scene_by_name[summary.scene];
      const RunResult& result = summary.median;
      std::map<std::string, std::string> values = {
          {"scene", summary.scene},
          {"engine", summary.engine},
          {"threads", std::to_string(summary.threads)},
          {"solver", summary.solver},
          {"steps", std::to_string(result.steps)},
          {"ms_per_step_median", Number(summary.ms_median)},
          {"max_penetration_m", Number(result.peak_penetration)},
          {"bodies", std::to_string(summary.bodies)},
          {"sim_seconds", Number(summary.seconds)},
          {"ms_per_step_min", Number(summary.ms_min)},
          {"ms_per_step_max", Number(summary.ms_max)},
          {"steps_per_second", Number(1e3 / summary.ms_median)},
          {"awake_seconds", Number(result.awake_steps * summary.time_step)},
          {"time_step_s", Number(summary.time_step)},
          {"final_kinetic_energy_j", Number(result.final_kinetic_energy)},
          {"final_penetration_m", Number(result.final_penetration)},
          {"broad_phase_ms", Number(result.broad_phase_ms)},
          {"narrow_phase_ms", Number(result.narrow_phase_ms)},
          {"solver_ms", Number(result.solver_ms)},
          {"integrator_ms", Number(result.integrator_ms)},
          {"solver_ns_per_row_iteration", Number(RowCostNs(result))},
          {"peak_rss_kb", std::to_string(summary.peak_rss_kb)},
          {"contact_seconds", Number(result.contact_steps * summary.time_step)},
          {"ms_per_contact_step", Number(ContactStepMs(result))}};
      if (summary.awake_ms_median > 0.0) {
        values["ms_per_awake_step_median"] = Number(summary.awake_ms_median);
      }
      AddRatioValues(summary, &values);
      if (!scene.articulations.empty()) {
        values["energy_drift"] = Number(result.energy_drift);
        values["energy_growth"] = Number(result.energy_growth);
        values["energy_start_j"] = Number(result.energy_start);
        values["servo_error_rad"] = Number(result.servo_error);
        values["diverged_runs"] = std::to_string(summary.diverged_runs);
      }
      AddSceneValues(scene, result, &values);
      WriteCsvLine(values, csv);
    }
  }
}

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
    WriteCsvLine({{"scene", "hull"},
                  {"engine", "ours"},
                  {"threads", "1"},
                  {"steps", "1"},
                  {"bodies", "1"},
                  {"ms_per_step_median", Number(total_ms)},
                  {"ms_per_step_min", Number(total_ms)},
                  {"ms_per_step_max", Number(total_ms)}},
                 csv);
  }
}

}  // namespace rigid_body_sim::bench
