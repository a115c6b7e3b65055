// The whole per-joint identification of `imscal identify` (backlash, cells, order sweep per
// cell, final fits, stability, validation) for 6 joints with 1 M samples each (~33 min at 2 ms),
// with the shipped default sweep (na, nb 1..32, d 0..4, BIC; 3 speed x 2 payload cells).
// Goal (issue 5): < 2 s for all 6 joints.
//
//   bench_identify --summary     one timed run (wall and CPU seconds) and the cells chosen
//   bench_identify               the Google Benchmark entry
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <numbers>
#include <vector>

#include "core/config_node.hpp"
#include "ident/identification_config.hpp"
#include "ident/joint_identification.hpp"
#include "tests/ident/joint_simulation.hpp"

namespace {
namespace ident = imscal::ident;

constexpr std::size_t kSamples = 1'000'000;
constexpr std::size_t kJoints = 6;
constexpr double kDt = 0.002;
const char* const kNames[kJoints] = {"A1", "A2", "A3", "A4", "A5", "A6"};

struct Data {
  std::vector<imscal::test_support::JointRecord> joints;
  std::vector<double> payload;
  ident::IdentificationConfig config;
};

const Data& data() {
  static const Data d = [] {
    Data out;
    for (std::size_t j = 0; j < kJoints; ++j) {
      imscal::test_support::SimulatedJoint joint;
      joint.backlash_l_rad = 0.5e-3 * double(j % 3);
      joint.pole_modulus = 0.9 + 0.01 * double(j);
      joint.dead_time = int(j % 4);
      joint.measurement_noise_rad = 1e-5;
      joint.frequency_hz = {0.2 + 0.03 * double(j), 0.7};
      out.joints.push_back(imscal::test_support::simulate_joint(joint, kSamples, kDt, unsigned(j)));
    }
    out.payload.assign(kSamples, 5.0);
    const auto config = imscal::ConfigNode::load_file(
        std::string(IMSCAL_SOURCE_DIR) + "/datasets/identification/ident-default.yaml");
    out.config = ident::load_identification_config(config);
    return out;
  }();
  return d;
}

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::vector<ident::JointIdentification> identify_all() {
  const Data& d = data();
  const std::vector<std::pair<std::size_t, std::size_t>> segments{{0, kSamples}};
  std::vector<ident::JointIdentification> out;
  for (std::size_t j = 0; j < kJoints; ++j)
    out.push_back(ident::identify_joint(kNames[j], d.joints[j].q_desired, d.joints[j].q_measured,
                                        d.payload, segments, kDt, d.config.joint_grid(j),
                                        d.config.options));
  return out;
}

void BM_Identify6Joints1M(benchmark::State& state) {
  data();
  for (auto _ : state) benchmark::DoNotOptimize(identify_all());
}
BENCHMARK(BM_Identify6Joints1M)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "--summary") == 0) {
    data();
    const auto wall0 = std::chrono::steady_clock::now();
    const double cpu0 = cpu_seconds();
    const auto result = identify_all();
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    std::printf("6 joints x %zu samples: %.3f s wall, %.3f s CPU\n", kSamples, wall,
                cpu_seconds() - cpu0);
    for (const auto& r : result) {
      std::printf("%s backlash l %.4g rad (1 sigma %.2g)\n", r.parameters.name.c_str(),
                  r.parameters.backlash_l_rad, r.parameters.backlash_l_sigma_rad);
      for (const auto& c : r.cells) {
        if (c.status != ident::CellStatus::kIdentified) continue;
        std::printf("  cell %d %-36s %-16s sim fit %7.2f %%, scaled condition %.2g (%s)\n", c.cell,
                    c.label.c_str(), ident::to_string(c.sweep->chosen).c_str(),
                    r.parameters.cells[std::size_t(c.cell)].figures.simulation_fit_percent,
                    c.fit->scaled_condition,
                    c.fit->method_used == ident::LeastSquaresMethod::kQr ? "QR" : "normal eq.");
      }
    }
    return 0;
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
