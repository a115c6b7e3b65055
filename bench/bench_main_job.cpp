// Speed of the main command (goal: `imscal run` on the shipped default campaign < 60 s on
// 2 cores, a second run with nothing changed < 5 s), timed as a user meets it: the imscal binary
// as a child process, wall time (UseManualTime). The baseline in the same run is
// `imscal simulate --scenario campaign`, which writes the campaign's raw files in the first
// place: the chain's cost is quoted as a ratio to it, since these machines are noisy.
//   bench/bench_main_job --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/subprocess.hpp"

namespace {
namespace fs = std::filesystem;

const fs::path kRunConfig = fs::path(IMSCAL_SOURCE_DIR) / "datasets/campaign/run.yaml";

fs::path scratch(const char* name) {
  const fs::path dir = fs::temp_directory_path() / (std::string("imscal-bench-main-job-") + name);
  fs::remove_all(dir);
  return dir;
}

// Runs imscal with `arguments`; returns the wall time [s]; throws when it fails.
double timed_imscal(const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{IMSCAL_BINARY};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  imscal::SubprocessOptions options;
  options.timeout_s = 600.0;
  const auto start = std::chrono::steady_clock::now();
  const auto result = imscal::run_subprocess(argv, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (result.exit_code != 0)
    throw std::runtime_error("imscal " + arguments.front() + " failed:\n" + result.output);
  return seconds;
}

void BM_SimulateCampaign_Baseline(benchmark::State& state) {
  const fs::path out = scratch("simulate");
  for (auto _ : state) {
    state.SetIterationTime(
        timed_imscal({"simulate", "--scenario", "campaign", "--out", out.string(), "--force"}));
  }
  fs::remove_all(out);
}

void BM_MainJob_FirstRun(benchmark::State& state) {
  const fs::path out = scratch("first");
  for (auto _ : state) {
    fs::remove_all(out);
    state.SetIterationTime(timed_imscal({"run", kRunConfig.string(), "--out", out.string()}));
  }
  fs::remove_all(out);
}

void BM_MainJob_SecondRunNothingChanged(benchmark::State& state) {
  const fs::path out = scratch("second");
  timed_imscal({"run", kRunConfig.string(), "--out", out.string()});  // the first run, untimed
  for (auto _ : state) {
    state.SetIterationTime(timed_imscal({"run", kRunConfig.string(), "--out", out.string()}));
  }
  fs::remove_all(out);
}

BENCHMARK(BM_SimulateCampaign_Baseline)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(3);
BENCHMARK(BM_MainJob_FirstRun)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(3);
BENCHMARK(BM_MainJob_SecondRunNothingChanged)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
