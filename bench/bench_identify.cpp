// The whole per-joint identification of `imscal identify` (backlash, cells, order sweep per
// cell, final fits, stability, validation) for 6 joints with 1 M samples each (~33 min at 2 ms),
// with two shipped configs:
//   paper    datasets/identification/ident-paper.yaml: the paper's eq. 2 ARX per cell, sweep na,
//            nb 1..32 and d 0..4 with BIC, 3 speed x 2 payload cells, eq. 3's backlash, on known
//            ARX joints with backlash (tests/ident/joint_simulation.hpp).
//   default  datasets/identification/ident-default.yaml: imscal's inverse form with the model
//            torque, direction, torque-sign and transmission-error inputs (60 + 60 + 1 + 32 + 32
//            further coefficients in every candidate of the same sweep; --summary also times it
//            without the transmission-error pair, as the default was before it, in the same
//            run), one cell, on the simulator's `identification` run
//            (the plant's true joint errors and the KDL model torques, 130 s) repeated as
//            separate runs up to 1 M samples, each repetition with its own white measurement
//            noise of 0.03 mrad (the IMS chain's error on this record, test_verification.cpp):
//            the regressors and their conditioning are those of a real identification.
// Goal: < 2 s for all 6 joints x 1 M samples. Timed as `imscal identify` runs it
// (ident::identify_joints: the independent joints on the machine's cores), with the same work on
// one thread in the same run as the baseline.
//
//   bench_identify --summary     one timed run each (wall and CPU seconds) and the cells chosen
//   bench_identify               the Google Benchmark entries
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <numbers>
#include <random>
#include <vector>

#include "core/config_node.hpp"
#include "eval/model_torque.hpp"
#include "eval/verification.hpp"
#include "ident/identification_config.hpp"
#include "ident/identify_joints.hpp"
#include "ident/joint_identification.hpp"
#include "sim/scenario.hpp"
#include "tests/ident/joint_simulation.hpp"

namespace {
namespace ident = imscal::ident;

constexpr std::size_t kSamples = 1'000'000;
constexpr std::size_t kJoints = 6;
constexpr double kDt = 0.002;
const char* const kNames[kJoints] = {"A1", "A2", "A3", "A4", "A5", "A6"};

struct Data {
  ident::JointErrorLog known_arx;       // the paper config's data
  ident::JointErrorLog identification;  // the default config's data
  ident::IdentificationConfig paper, shipped_default;
  ident::IdentificationConfig without_transmission_error;  // the default without the pair
};

// Known ARX joints with backlash, 1 M samples each.
ident::JointErrorLog known_arx_log() {
  ident::JointErrorLog log;
  log.cycle_s = kDt;
  for (std::size_t j = 0; j < kJoints; ++j) {
    imscal::test_support::SimulatedJoint joint;
    joint.backlash_l_rad = 0.5e-3 * double(j % 3);
    joint.pole_modulus = 0.9 + 0.01 * double(j);
    joint.dead_time = int(j % 4);
    joint.measurement_noise_rad = 1e-5;
    joint.frequency_hz = {0.2 + 0.03 * double(j), 0.7};
    auto record = imscal::test_support::simulate_joint(joint, kSamples, kDt, unsigned(j));
    if (j == 0) log.time_s = record.t_s;
    log.joint_names.push_back(kNames[j]);
    log.q_desired_rad.push_back(std::move(record.q_desired));
    log.q_measured_rad.push_back(std::move(record.q_measured));
  }
  log.payload_kg.assign(kSamples, 5.0);
  return log;
}

// The `identification` scenario's true joint errors with the model torques the default config
// reads, repeated (1 s apart: separate runs) up to kSamples, white noise per repetition.
ident::JointErrorLog tiled_identification_log(const ident::IdentificationConfig& config) {
  namespace eval = imscal::eval;
  const imscal::sim::Scenario scenario = imscal::sim::load_scenario(
      std::string(IMSCAL_SOURCE_DIR) + "/datasets/scenarios/identification.yaml");
  ident::JointErrorLog one = eval::simulate_truth_joint_errors(scenario);
  eval::attach_model_torques(one, eval::scenario_model_torque(scenario), config.options);
  const std::size_t n = one.sample_count();
  const double period_s = one.time_s.back() - one.time_s.front() + 1.0;
  ident::JointErrorLog log = one;
  log.time_s.clear();
  log.payload_kg.clear();
  for (auto* signals :
       {&log.q_desired_rad, &log.q_measured_rad, &log.q_internal_rad, &log.model_torque_nm})
    for (auto& joint : *signals) joint.clear();
  std::mt19937_64 rng(5);
  std::normal_distribution<double> measurement_noise_rad(0.0, 0.03e-3);
  for (std::size_t repeat = 0; log.sample_count() < kSamples; ++repeat) {
    const std::size_t take = std::min(n, kSamples - log.sample_count());
    for (std::size_t k = 0; k < take; ++k) {
      log.time_s.push_back(one.time_s[k] + double(repeat) * period_s);
      log.payload_kg.push_back(one.payload_kg[k]);
    }
    auto append = [take](std::vector<double>& to, const std::vector<double>& from) {
      to.insert(to.end(), from.begin(), from.begin() + std::ptrdiff_t(take));
    };
    for (std::size_t j = 0; j < one.joint_count(); ++j) {
      append(log.q_desired_rad[j], one.q_desired_rad[j]);
      append(log.q_internal_rad[j], one.q_internal_rad[j]);
      if (!one.model_torque_nm.empty()) append(log.model_torque_nm[j], one.model_torque_nm[j]);
      for (std::size_t k = 0; k < take; ++k)
        log.q_measured_rad[j].push_back(one.q_measured_rad[j][k] + measurement_noise_rad(rng));
    }
  }
  ident::split_at_gaps(log);
  return log;
}

ident::IdentificationConfig config_of(const char* file) {
  return ident::load_identification_config(imscal::ConfigNode::load_file(
      std::string(IMSCAL_SOURCE_DIR) + "/datasets/identification/" + file));
}

const Data& data() {
  static const Data d = [] {
    Data out;
    out.paper = config_of("ident-paper.yaml");
    out.shipped_default = config_of("ident-default.yaml");
    out.without_transmission_error = out.shipped_default;
    out.without_transmission_error.options.transmission_error_input = false;
    out.known_arx = known_arx_log();
    out.identification = tiled_identification_log(out.shipped_default);
    return out;
  }();
  return d;
}

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

enum class Config { kPaper, kDefault, kDefaultWithoutTransmissionError };

// threads: 0 = every core (as `imscal identify`), 1 = the sequential baseline. Each config on
// its own data (see the header).
std::vector<ident::JointOutcome> identify_all(Config config, unsigned threads) {
  switch (config) {
    case Config::kPaper:
      return ident::identify_joints(data().known_arx, data().paper, threads);
    case Config::kDefault:
      return ident::identify_joints(data().identification, data().shipped_default, threads);
    case Config::kDefaultWithoutTransmissionError:
      break;
  }
  return ident::identify_joints(data().identification, data().without_transmission_error, threads);
}

// Arg 0: the config (0 paper, 1 default); arg 1: threads (1 baseline, 0 all cores). Wall time:
// the goal is the user's wait.
void BM_Identify6Joints1M(benchmark::State& state) {
  for (auto _ : state)
    benchmark::DoNotOptimize(identify_all(state.range(0) == 1 ? Config::kDefault : Config::kPaper,
                                          unsigned(state.range(1))));
}
BENCHMARK(BM_Identify6Joints1M)
    ->Args({0, 1})
    ->Args({0, 0})
    ->Args({1, 1})
    ->Args({1, 0})
    ->ArgNames({"default_config", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "--summary") == 0) {
    data();
    for (const Config config :
         {Config::kPaper, Config::kDefault, Config::kDefaultWithoutTransmissionError}) {
      std::printf("%s\n",
                  config == Config::kPaper
                      ? "paper config (ident-paper.yaml: eq. 2 ARX, 3 x 2 cells, backlash) on "
                        "known ARX joints; goal < 2 s"
                  : config == Config::kDefault
                      ? "default config (ident-default.yaml: inverse form, 60-tap torque and "
                        "direction inputs, 32-tap transmission-error pair, one cell) on the "
                        "simulated identification run, repeated; goal < 2 s"
                      : "the default without the transmission-error pair (the former "
                        "default), the same run");
      // All cores first: the first run also pays the first touches of memory, so the ratio to
      // the one-thread baseline after it is on the safe side.
      std::vector<ident::JointOutcome> result;
      double parallel_wall = 0.0;
      for (const unsigned threads : {0u, 1u}) {
        const auto wall0 = std::chrono::steady_clock::now();
        const double cpu0 = cpu_seconds();
        auto outcomes = identify_all(config, threads);
        const double wall =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
        std::printf("  6 joints x %zu samples, %s: %.3f s wall, %.3f s CPU", kSamples,
                    threads == 1 ? "one thread (baseline)" : "all cores (imscal identify)", wall,
                    cpu_seconds() - cpu0);
        if (threads == 0) {
          parallel_wall = wall;
          result = std::move(outcomes);
        } else {
          std::printf("; all cores %.2fx faster", wall / parallel_wall);
        }
        std::printf("\n");
      }
      for (const auto& outcome : result) {
        const auto& r = outcome.result;
        if (!outcome.failure.empty())
          std::printf("  not identified: %s\n", outcome.failure.c_str());
        std::printf("  %s backlash l %.4g rad (1 sigma %.2g)\n", r.parameters.name.c_str(),
                    r.parameters.backlash_l_rad, r.parameters.backlash_l_sigma_rad);
        for (const auto& c : r.cells) {
          if (!c.fit) continue;
          std::printf(
              "    cell %d %-36s %-16s sim fit %7.2f %%, scaled condition %.2g (%s, %d "
              "refinement steps)\n",
              c.cell, c.label.c_str(), ident::to_string(c.sweep->chosen).c_str(),
              r.parameters.cells[std::size_t(c.cell)].figures.simulation_fit_percent,
              c.fit->scaled_condition, ident::to_string(c.fit->method_used),
              c.fit->refinement_steps);
        }
      }
    }
    return 0;
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
