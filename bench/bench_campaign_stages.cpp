// The shipped campaign's `imscal run`, stage by stage (goal: the whole run <= 4 s wall on 2
// cores). Each iteration runs the chain into a fresh folder as a child process and reads every
// stage's wall and CPU time from its stage.json (`seconds`, `cpu_seconds`: the stage's threads and
// its subprocess, user plus system); the whole run's CPU time comes from wait4. Since these
// machines are shared and loaded, CPU time is the figure to compare, and the baseline runs in the
// same iterations: the binary named by IMSCAL_BASELINE_BINARY (e.g. an earlier build of main),
// alternately with this build's, so that `ratio_cpu` and `ratio_wall` (this build over the
// baseline) hold under the same load. A baseline without `cpu_seconds` in its records gives its
// stages' wall time only.
//   IMSCAL_BASELINE_BINARY=/path/to/old/imscal bench/bench_campaign_stages
//   (add --benchmark_counters_tabular=true for a table; --benchmark_report_aggregates_only=true
//   for the aggregates of the five repetitions alone)
#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace {
namespace fs = std::filesystem;

const fs::path kRunConfig = fs::path(IMSCAL_SOURCE_DIR) / "datasets/campaign/run.yaml";
const std::vector<std::string> kStages = {"validate", "calibrate", "identify",
                                          "verify",   "diagnose",  "report"};

struct Timing {
  double wall_s = 0.0, cpu_s = 0.0;
  std::map<std::string, double> stage_wall_s, stage_cpu_s;
};

// `binary run` on the shipped campaign into a fresh `folder`; throws when it fails.
Timing run_campaign(const std::string& binary, const fs::path& folder) {
  fs::remove_all(folder);
  fs::create_directories(folder.parent_path());
  const fs::path log = folder.string() + ".log";
  const imscal::bench::ChildRun run =
      imscal::bench::run_child({binary, "run", kRunConfig.string(), "--out", folder.string()}, log);
  Timing t;
  t.wall_s = run.wall_s;
  t.cpu_s = run.cpu_s;
  for (const std::string& stage : kStages) {
    std::ifstream in(folder / stage / "stage.json");
    if (!in) continue;
    const nlohmann::json record = nlohmann::json::parse(in);
    t.stage_wall_s[stage] = record.value("seconds", 0.0);
    if (record.contains("cpu_seconds")) t.stage_cpu_s[stage] = record["cpu_seconds"].get<double>();
  }
  return t;
}

// Adds `t` to `sum`.
void add(Timing& sum, const Timing& t) {
  sum.wall_s += t.wall_s, sum.cpu_s += t.cpu_s;
  for (const auto& [stage, s] : t.stage_wall_s) sum.stage_wall_s[stage] += s;
  for (const auto& [stage, s] : t.stage_cpu_s) sum.stage_cpu_s[stage] += s;
}

// The mean per iteration of `sum` as counters named with `prefix`.
void set_counters(benchmark::State& state, const std::string& prefix, const Timing& sum) {
  const double n = double(std::max<benchmark::IterationCount>(state.iterations(), 1));
  state.counters[prefix + "wall_s"] = sum.wall_s / n;
  state.counters[prefix + "cpu_s"] = sum.cpu_s / n;
  for (const auto& [stage, s] : sum.stage_wall_s)
    state.counters[prefix + stage + "_wall_s"] = s / n;
  for (const auto& [stage, s] : sum.stage_cpu_s) state.counters[prefix + stage + "_cpu_s"] = s / n;
}

void BM_CampaignRun_StageByStage(benchmark::State& state) {
  const char* baseline = std::getenv("IMSCAL_BASELINE_BINARY");
  const fs::path scratch = fs::temp_directory_path() / "imscal-bench-campaign-stages";
  Timing ours, base;
  for (auto _ : state) {
    if (baseline && *baseline) add(base, run_campaign(baseline, scratch / "baseline"));
    const Timing t = run_campaign(IMSCAL_BINARY, scratch / "this");
    add(ours, t);
    state.SetIterationTime(t.wall_s);
  }
  set_counters(state, "", ours);
  if (base.wall_s > 0.0) {
    set_counters(state, "base_", base);
    state.counters["ratio_wall"] = ours.wall_s / base.wall_s;
    state.counters["ratio_cpu"] = ours.cpu_s / base.cpu_s;
  }
  fs::remove_all(scratch);
}

// Five repetitions of one run each (this build's and the baseline's alternating): the aggregates
// give the mean, median, spread (stddev) and the fastest and slowest of the five.
BENCHMARK(BM_CampaignRun_StageByStage)
    ->UseManualTime()
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->Repetitions(5)
    ->ComputeStatistics("min",
                        [](const std::vector<double>& v) {
                          return *std::min_element(v.begin(), v.end());
                        })
    ->ComputeStatistics("max", [](const std::vector<double>& v) {
      return *std::max_element(v.begin(), v.end());
    });

}  // namespace

BENCHMARK_MAIN();
