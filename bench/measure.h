// Runs of a benchmark scene: one engine simulating one scene in a child
// process, and the runs of every engine under test summed up per scene.
#ifndef RIGID_BODY_SIM_BENCH_MEASURE_H_
#define RIGID_BODY_SIM_BENCH_MEASURE_H_

#include <string>
#include <vector>

#include "engine.h"
#include "scene.h"

namespace rigid_body_sim::bench {

// What one run measures; plain data, sent from the child through a pipe.
struct RunResult {
  bool ok = false;
  int steps = 0;
  double step_ms = 0.0;         // wall ms per step, mean over the run
  double window_step_ms = 0.0;  // the same over the first window_seconds of the run
  // The steps with contact points within that window, and their wall time.
  int window_contact_steps = 0;
  double window_contact_ms = 0.0;
  // Steps in which every body that can move was awake
  // (Engine::AllMovingBodiesAwake), and their wall time in all.
  int awake_steps = 0;
  double awake_ms = 0.0;
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
  double joint_separation = 0.0;      // m, articulations: largest over the run
  double boxes_moved = 0.0;           // arm: free bodies moved over 1 cm (a count)
  double driven_swept = 0.0;          // rad, arm: farthest the driven joint turned from its start
  double driven_commanded = 0.0;
  // Terrain: s until no body moved faster than 0.05 m/s (the sleep
  // threshold) any more, and the bodies whose centre ended below the surface.
  double settle_time = 0.0;
  double below_surface = 0.0;
  // Articulated scenes, from Engine::MechanicalEnergy after every step:
  // the change from the start at the end and the largest growth over the
  // run, each as a fraction of the scene's EnergyScale (+inf when the
  // energy turned non-finite), and whether the run diverged (kDivergedGrowth).
  double energy_drift = 0.0;
  double energy_growth = 0.0;
  double energy_start = 0.0;  // J
  bool diverged = false;
  // rad, scenes with motors: the largest distance over the run of a motored
  // joint from where its commanded velocities would have taken it.
  double servo_error = 0.0;
  long peak_rss_kb = 0;  // filled in by the parent
};

// A run diverged when its mechanical energy grew by more than this fraction
// of the scene's energy scale at any step, or turned non-finite; its time
// is then no engine's ratio's denominator (MeasureEngines).
constexpr double kDivergedGrowth = 0.10;

// wall ms per step of the steps with every moving body awake; 0 when none.
inline double AwakeStepMs(const RunResult& result) {
  return result.awake_steps > 0 ? result.awake_ms / result.awake_steps : 0.0;
}

// Wall ms of one step that had contact points to solve.
inline double ContactStepMs(const RunResult& result) {
  return result.contact_steps > 0 ? result.contact_steps_ms / result.contact_steps : 0.0;
}

struct Summary {
  std::string scene;
  std::string engine;
  int threads = 1;
  std::string solver;  // EngineSolver: ours' motion solver, "" for the other engines
  int bodies = 0;
  double seconds = 0.0;
  double time_step = kDefaultTimeStep;  // s
  int diverged_runs = 0;
  RunResult median;  // the median run by time, with each quality figure's median
  double ms_median = 0.0;
  double ms_min = 0.0;
  double ms_max = 0.0;
  // Median over the runs that had any awake step of their ms per awake
  // step; 0 when none had.
  double awake_ms_median = 0.0;
  long peak_rss_kb = 0;  // largest over the runs
  // Every row but ours on one thread with the exact solver: the medians
  // over the runs of that engine / this row's, ms per step and ms per awake
  // step, each pair of runs made back to back (MeasureEngines); 0 when not
  // measured. Runs that diverged, this engine's or ours, give no ratio.
  double ours_over_this = 0.0;
  double ours_over_this_awake = 0.0;
  // The same for ours on two threads (exact) over this row, when it ran.
  double ours2_over_this = 0.0;
  double ours2_over_this_awake = 0.0;
  // The same for ours with the soft step, on one and on two threads: on
  // the exact rows, how much of ours' time the soft step takes.
  double soft_over_this = 0.0;
  double soft_over_this_awake = 0.0;
  double soft2_over_this = 0.0;
  double soft2_over_this_awake = 0.0;
};

// The engine's name, then ours' solver when it is not the exact one, then
// its threads when more than one: "ours", "ours x2", "ours soft_step x2".
std::string EngineLabel(const Summary& summary);

// How every run of a benchmark is made.
struct RunSettings {
  double window_seconds = 10.0;  // s; the stage profile's window (RunResult)
  OurSettingsOverrides overrides;
};

// Runs a scene in each engine of `engines` (ours first), run k of each
// right after another, so that a change in the shared machine's load
// between runs reaches every engine alike. One summary per engine, in the
// order of `engines`.
std::vector<Summary> MeasureEngines(const Scene& scene, int runs, const RunSettings& settings,
                                    const std::vector<EngineKind>& engines);

}  // namespace rigid_body_sim::bench

#endif  // RIGID_BODY_SIM_BENCH_MEASURE_H_
