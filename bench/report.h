// What physics_bench prints and writes: a row per scene and engine, the
// stage profile, the scaling of the piles, and the CSV.
#ifndef RIGID_BODY_SIM_BENCH_REPORT_H_
#define RIGID_BODY_SIM_BENCH_REPORT_H_

#include <fstream>
#include <string>
#include <vector>

#include "measure.h"
#include "scene.h"

namespace rigid_body_sim::bench {

// Per scene, one summary per engine, ours first.
using Rows = std::vector<std::vector<Summary>>;

void PrintTableHeader();
// The rows of one scene, as MeasureEngines returned them.
void PrintSceneRows(const Scene& scene, const std::vector<Summary>& summaries);
// Stage profile and the cost of one contact row in one solver iteration.
void PrintStageProfile(const Rows& rows);
// Scaling from pile_1000 to pile_4000 over their first window_seconds.
void PrintScaling(const Rows& rows, double window_seconds);

// The CSV's columns: those of issue 25 first, then the rest of the report.
const std::vector<std::string>& CsvColumns();
void WriteCsv(const std::vector<Scene>& scenes, const Rows& rows, std::ofstream& csv);
// Runs the hull benchmark binary and adds its row to the CSV.
void RunHullBench(const std::string& hull_bench, std::ofstream& csv);

}  // namespace rigid_body_sim::bench

#endif  // RIGID_BODY_SIM_BENCH_REPORT_H_
