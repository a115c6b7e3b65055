// Lab-scale records through the main command (goals: a 30-minute session at 2 kHz through
// `imscal run` < 60 s wall on 2 cores and < 2 GB peak memory; the cost per recorded minute flat
// at 5, 15 and 30 minutes). Each session is simulated once, outside the timing, into a temporary
// folder (kept for the next run: /tmp/imscal-bench-lab-scale-MINUTES/): the shipped campaign's
// program (datasets/programs/campaign.yaml: rest poses for the frame calibration, full-speed moves
// for the identification) repeated to the length, on the campaign's scenario with the IMS at 2 kHz,
// with the campaign's configs (the paper's line in the verify stage). Timed: the imscal binary's
// `run` as a child process, wall time (UseManualTime), and its peak resident memory (wait4's
// rusage: the largest of the child and its stages' subprocesses) and CPU time (user + system),
// each also per recorded minute. The shipped 70 s campaign at 1 kHz is the baseline in the same
// run. BM_LabScaleCalibrate times `imscal calibrate` alone on the same records (the stage whose
// memory grew with the record: the smoother's trajectory, ims/zupt_smoother.hpp).
//   bench/bench_lab_scale --benchmark_counters_tabular=true
//   bench/bench_lab_scale --benchmark_filter='Run/(0|5)/'   (the baseline and 5 minutes only)
//   bench/bench_lab_scale --benchmark_filter='Calibrate'    (calibrate alone)
// BM_LabScaleCalibrate/MINUTES/1 times the `calibrate` of the binary named by
// IMSCAL_BENCH_BASELINE on the same record, right before this build's (/MINUTES/0): the
// before/after ratio measured in one run (skipped when the variable is not set):
//   IMSCAL_BENCH_BASELINE=/path/to/main/imscal bench/bench_lab_scale --benchmark_filter=Calibrate
#include <benchmark/benchmark.h>

#include "child_process.hpp"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace {
namespace fs = std::filesystem;

const fs::path kSource(IMSCAL_SOURCE_DIR);

using imscal::bench::ChildRun;

// Runs imscal (this build's, or `binary`) with `arguments`, its output into `log`; throws when
// it fails.
ChildRun run_imscal(const std::vector<std::string>& arguments, const fs::path& log,
                    const std::string& binary = IMSCAL_BINARY) {
  std::vector<std::string> words{binary};
  words.insert(words.end(), arguments.begin(), arguments.end());
  return imscal::bench::run_child(std::move(words), log);
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

// The campaign program with its moves and rests after the first (alignment) rest repeated to
// fill `minutes`.
std::string session_program(int minutes) {
  const std::string campaign = read_text(kSource / "datasets/programs/campaign.yaml");
  const std::size_t segments = campaign.find("segments:\n");
  const std::size_t first = campaign.find('\n', campaign.find("- rest:", segments)) + 1;
  const std::string head = campaign.substr(0, first), body = campaign.substr(first);
  const double body_s = 60.0;  // 13 poses: 12 moves and 12 rests of 4 s, ~61 s
  const int repeats = std::max(1, int(std::ceil((minutes * 60.0 - 10.0) / body_s)));
  std::string out = head;
  for (int i = 0; i < repeats; ++i) out += body;
  return out;
}

// <data>/robots and <data>/sensors as links to this source tree's folders (a kept session's
// links may point to a source tree that is gone).
void link_shared_folders(const fs::path& data) {
  for (const char* shared : {"robots", "sensors"}) {
    const fs::path link = data / shared, target = kSource / "datasets" / shared;
    if (fs::is_symlink(link) && fs::read_symlink(link) == target) continue;
    if (fs::is_symlink(link)) fs::remove(link);
    if (!fs::exists(link)) fs::create_directory_symlink(target, link);
  }
}

// A session folder <root>/datasets/session/ laid out like datasets/campaign/ (whose configs it
// copies; their ../robots etc. resolve through links to the shipped folders).
fs::path make_session(const fs::path& root, int minutes) {
  const fs::path data = root / "datasets";
  fs::create_directories(root);
  fs::create_directories(data / "programs");
  fs::create_directories(data / "scenarios");
  fs::create_directories(data / "session");
  link_shared_folders(data);
  fs::copy_file(kSource / "datasets/programs/seed-line.yaml", data / "programs/seed-line.yaml",
                fs::copy_options::overwrite_existing);
  write_text(data / "programs/session.yaml", session_program(minutes));
  std::string scenario = read_text(kSource / "datasets/scenarios/campaign.yaml");
  const auto replace = [&](const std::string& from, const std::string& to) {
    const std::size_t at = scenario.find(from);
    if (at == std::string::npos) throw std::runtime_error("campaign scenario: no " + from);
    scenario.replace(at, from.size(), to);
  };
  replace("programs/campaign.yaml", "programs/session.yaml");
  replace("rate_hz: 1000", "rate_hz: 2000");
  replace("output_interval_s: 0.001", "output_interval_s: 0.0005");
  write_text(data / "scenarios/session.yaml", scenario);
  const fs::path sim = root / "sim", session = data / "session";
  run_imscal({"simulate", "--scenario", (data / "scenarios/session.yaml").string(), "--out",
              sim.string(), "--force"},
             root / "simulate.log");
  fs::rename(sim / "imu.csv", session / "imu.csv");
  fs::rename(sim / "robot.csv", session / "robot.csv");
  // The unit's lab calibration: the drawn scale factors and misalignments, biases zero (as
  // datasets/campaign/regenerate.sh writes it).
  std::istringstream errors(read_text(sim / "truth/sensor_errors.yaml"));
  std::string unit, line;
  while (std::getline(errors, line)) {
    if (line.rfind("  bias_deg_per_h:", 0) == 0) line = "  bias_deg_per_h: [0, 0, 0]";
    if (line.rfind("  bias_ug:", 0) == 0) line = "  bias_ug: [0, 0, 0]";
    unit += line + "\n";
  }
  write_text(session / "unit-calibration.yaml", unit);
  fs::remove_all(sim);
  for (const char* config : {"run.yaml", "calibrate.yaml", "identify.yaml", "verify-line.yaml"})
    fs::copy_file(kSource / "datasets/campaign" / config, session / config,
                  fs::copy_options::overwrite_existing);
  return session / "run.yaml";
}

// The recorded length [min]: the last time stamp of the robot log.
double record_minutes(const fs::path& run_config) {
  std::ifstream in(run_config.parent_path() / "robot.csv");
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return std::stod(last.substr(0, last.find(','))) / 60.0;
}

// Each stage's wall time as `imscal run` prints it ("calibrate 12.3 s, ..."), from its output.
std::string stage_times(const fs::path& log) {
  std::istringstream in(read_text(log));
  std::string line, out;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string stage, what, status, seconds, unit;
    if (!(words >> stage >> what >> status >> seconds >> unit) || what != "ran" || unit != "s")
      continue;
    out += (out.empty() ? "" : " ") + stage + " " + seconds;
  }
  return out;
}

// The counters of one child run over a record of `recorded_min` minutes.
void set_counters(benchmark::State& state, const ChildRun& r, double recorded_min) {
  state.counters["record_min"] = recorded_min;
  state.counters["wall_s"] = r.wall_s;
  state.counters["s_per_record_min"] = r.wall_s / recorded_min;
  state.counters["peak_rss_MB"] = r.peak_rss_mb;
  state.counters["cpu_s"] = r.cpu_s;  // on a loaded machine the steadier figure (threads add up)
  state.counters["cpu_s_per_record_min"] = r.cpu_s / recorded_min;
}

// The run.yaml of argument 0, the shipped campaign (70 s at 1 kHz), or of a session of that
// many minutes, simulated on the first run and kept in `root` for the next (delete it to
// simulate again).
fs::path record_config(int minutes, const fs::path& root) {
  const fs::path kept = root / "datasets/session/run.yaml";
  if (minutes == 0) return kSource / "datasets/campaign/run.yaml";
  if (fs::exists(kept)) {
    link_shared_folders(root / "datasets");
    return kept;
  }
  fs::remove_all(root);
  return make_session(root, minutes);
}

fs::path bench_root(int minutes) {
  return fs::temp_directory_path() / ("imscal-bench-lab-scale-" + std::to_string(minutes));
}

void BM_LabScaleRun(benchmark::State& state) {
  const int minutes = int(state.range(0));
  const fs::path root = bench_root(minutes);
  const fs::path config = record_config(minutes, root);
  fs::create_directories(root);
  const double recorded_min = record_minutes(config);
  ChildRun r;
  for (auto _ : state) {
    fs::remove_all(root / "run");
    r = run_imscal({"run", config.string(), "--out", (root / "run").string()}, root / "run.log");
    state.SetIterationTime(r.wall_s);
  }
  state.SetLabel(stage_times(root / "run.log"));
  set_counters(state, r, recorded_min);
  fs::remove_all(root / "run");
}

// `imscal calibrate` of `binary` alone with the run's calibrate config on the same records.
void time_calibrate(benchmark::State& state, const std::string& binary) {
  const int minutes = int(state.range(0));
  const fs::path root = bench_root(minutes);
  const fs::path folder = record_config(minutes, root).parent_path();
  fs::create_directories(root);  // the campaign's (argument 0) is not made by record_config
  const double recorded_min = record_minutes(folder / "run.yaml");
  ChildRun r;
  for (auto _ : state) {
    r = run_imscal(
        {"calibrate", "--imu", (folder / "imu.csv").string(), "--robot-log",
         (folder / "robot.csv").string(), "--config", (folder / "calibrate.yaml").string(), "--out",
         (root / "calibrate").string(), "--force"},
        root / "calibrate.log", binary);
    state.SetIterationTime(r.wall_s);
  }
  set_counters(state, r, recorded_min);
  fs::remove_all(root / "calibrate");
}

// Argument 1: 0 this build's binary, 1 the baseline's (IMSCAL_BENCH_BASELINE).
void BM_LabScaleCalibrate(benchmark::State& state) {
  if (state.range(1) == 0) return time_calibrate(state, IMSCAL_BINARY);
  const char* baseline = std::getenv("IMSCAL_BENCH_BASELINE");
  if (baseline == nullptr) return state.SkipWithError("IMSCAL_BENCH_BASELINE is not set");
  time_calibrate(state, baseline);
}

BENCHMARK(BM_LabScaleRun)
    ->Arg(0)
    ->Arg(5)
    ->Arg(15)
    ->Arg(30)
    ->UseManualTime()
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

// Each record's baseline right before this build's, so that the two see the same load.
BENCHMARK(BM_LabScaleCalibrate)
    ->ArgsProduct({{0, 5, 15, 30}, {1, 0}})
    ->UseManualTime()
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
