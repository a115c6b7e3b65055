// The whole per-joint identification of `imscal identify` (backlash, cells, order sweep per
// cell, final fits, stability, validation) for 6 joints with 1 M samples each (~33 min at 2 ms),
// with two shipped configs:
//   paper    datasets/identification/ident-paper.yaml: the paper's eq. 2 ARX per cell, sweep na,
//            nb 1..32 and d 0..4 with BIC, 3 speed x 2 payload cells, eq. 3's backlash. Goal
//            (issue 5): < 2 s for all 6 joints.
//   default  datasets/identification/ident-default.yaml: imscal's inverse form with the model
//            torque, direction and torque-sign inputs (60 + 60 + 1 further coefficients in every
//            candidate of the same sweep), one cell. The torques are a synthetic rigid-body-like
//            signal (inertia x acceleration + gravity-like term of q_d): only the work is timed.
// Timed as `imscal identify` runs it (ident::identify_joints: the independent joints on the
// machine's cores), with the same work on one thread in the same run as the baseline.
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
#include "ident/identification_config.hpp"
#include "ident/identify_joints.hpp"
#include "ident/joint_identification.hpp"
#include "tests/ident/joint_simulation.hpp"

namespace {
namespace ident = imscal::ident;

constexpr std::size_t kSamples = 1'000'000;
constexpr std::size_t kJoints = 6;
constexpr double kDt = 0.002;
const char* const kNames[kJoints] = {"A1", "A2", "A3", "A4", "A5", "A6"};

struct Data {
  ident::JointErrorLog log;
  ident::IdentificationConfig paper, shipped_default;
};

ident::IdentificationConfig config_of(const char* file) {
  return ident::load_identification_config(imscal::ConfigNode::load_file(
      std::string(IMSCAL_SOURCE_DIR) + "/datasets/identification/" + file));
}

// A rigid-body-like joint torque along q_d [N m]: inertia x acceleration (central differences),
// a gravity-like sin(q_d) term and a low-passed random load (seeded), which keeps the torque
// from being a linear function of q_d's lags (the regression would be rank deficient). Only
// its shape matters here: the work does not depend on it.
std::vector<double> synthetic_torque(const std::vector<double>& q, double dt, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<double> tau(q.size(), 0.0);
  double load = 0.0;
  for (std::size_t k = 1; k + 1 < q.size(); ++k) {
    load = 0.999 * load + 0.05 * noise(rng);  // ~2 s correlation time at 2 ms
    tau[k] = 20.0 * (q[k + 1] - 2.0 * q[k] + q[k - 1]) / (dt * dt) + 80.0 * std::sin(q[k]) + load;
  }
  if (q.size() > 2) {
    tau.front() = tau[1];
    tau.back() = tau[q.size() - 2];
  }
  return tau;
}

const Data& data() {
  static const Data d = [] {
    Data out;
    out.log.cycle_s = kDt;
    for (std::size_t j = 0; j < kJoints; ++j) {
      imscal::test_support::SimulatedJoint joint;
      joint.backlash_l_rad = 0.5e-3 * double(j % 3);
      joint.pole_modulus = 0.9 + 0.01 * double(j);
      joint.dead_time = int(j % 4);
      joint.measurement_noise_rad = 1e-5;
      joint.frequency_hz = {0.2 + 0.03 * double(j), 0.7};
      auto record = imscal::test_support::simulate_joint(joint, kSamples, kDt, unsigned(j));
      if (j == 0) out.log.time_s = record.t_s;
      out.log.joint_names.push_back(kNames[j]);
      out.log.q_desired_rad.push_back(std::move(record.q_desired));
      out.log.q_measured_rad.push_back(std::move(record.q_measured));
    }
    out.log.payload_kg.assign(kSamples, 5.0);
    for (std::size_t j = 0; j < kJoints; ++j)
      out.log.model_torque_nm.push_back(
          synthetic_torque(out.log.q_desired_rad[j], kDt, 100u + unsigned(j)));
    out.paper = config_of("ident-paper.yaml");
    out.shipped_default = config_of("ident-default.yaml");
    return out;
  }();
  return d;
}

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// threads: 0 = every core (as `imscal identify`), 1 = the sequential baseline.
std::vector<ident::JointOutcome> identify_all(const ident::IdentificationConfig& config,
                                              unsigned threads) {
  return ident::identify_joints(data().log, config, threads);
}

// Arg 0: the config (0 paper, 1 default); arg 1: threads (1 baseline, 0 all cores). Wall time:
// the goal is the user's wait.
void BM_Identify6Joints1M(benchmark::State& state) {
  const ident::IdentificationConfig& config =
      state.range(0) == 0 ? data().paper : data().shipped_default;
  for (auto _ : state) benchmark::DoNotOptimize(identify_all(config, unsigned(state.range(1))));
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
    for (const bool shipped_default : {false, true}) {
      const ident::IdentificationConfig& config =
          shipped_default ? data().shipped_default : data().paper;
      std::printf("%s\n", shipped_default
                              ? "default config (ident-default.yaml: inverse form, 60-tap "
                                "torque and direction inputs, one cell)"
                              : "paper config (ident-paper.yaml: eq. 2 ARX, 3 x 2 cells, "
                                "backlash; issue 5's goal < 2 s)");
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
          if (c.status != ident::CellStatus::kIdentified) continue;
          std::printf("    cell %d %-36s %-16s sim fit %7.2f %%, scaled condition %.2g (%s)\n",
                      c.cell, c.label.c_str(), ident::to_string(c.sweep->chosen).c_str(),
                      r.parameters.cells[std::size_t(c.cell)].figures.simulation_fit_percent,
                      c.fit->scaled_condition,
                      c.fit->method_used == ident::LeastSquaresMethod::kQr ? "QR" : "normal eq.");
        }
      }
    }
    return 0;
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
