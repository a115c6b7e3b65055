// ARX identification speed: the order-32 fit and the order/dead-time sweep on 1 M samples.
//
// Besides the Google Benchmark entries, the first argument selects a mode used by
// bench/compare_arx_numpy.py (so that numpy and imscal work on the same file in one script run):
//   bench_arx --write-data FILE SAMPLES JOINTS SEED   simulate JOINTS known ARX systems (joint 0 is
//       na = nb = 32, d = 3; the others lower orders), write raw little-endian float64 blocks
//       [u_0, y_0, u_1, y_1, ...] of SAMPLES each, print the true structures and θ as JSON.
//   bench_arx --fit FILE NA NB D       fit one joint (the file's first block pair), print θ and
//       the best fit time of 3 as JSON.
//   bench_arx --identify FILE JOINTS   order sweep (na, nb 1..32, d 0..8, BIC) + final fit +
//       validation statistics for every joint, print the chosen structures and times as JSON.
//   bench_arx --fit-multi FILE METHOD NA NB D NX...   fit a multi-input model to the blocks
//       [u, y, x_0, x_1, ...] of FILE (one further input per NX) with METHOD (auto, normal,
//       refined, qr), print θ, σ, the method used and its refinement steps as JSON.
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <chrono>
#include <complex>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/atomic_file.hpp"
#include "ident/arx_fit.hpp"
#include "ident/model_validation.hpp"
#include "ident/order_selection.hpp"

namespace {

using imscal::ident::ArxModel;
using imscal::ident::ArxStructure;
using imscal::ident::IoSegment;

// Random stable system: conjugate pole pairs (one real pole for odd na) with modulus in
// [0.3, 0.9], input coefficients of magnitude [0.5, 1.5] with random sign.
ArxModel random_system(const ArxStructure& s, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> modulus(0.3, 0.9), angle(0.1, 3.0), unit(-1.0, 1.0),
      magnitude(0.5, 1.5);
  std::vector<std::complex<double>> c{1.0};
  auto multiply = [&](std::complex<double> pole) {
    c.push_back(0.0);
    for (std::size_t i = c.size() - 1; i > 0; --i) c[i] -= pole * c[i - 1];
  };
  for (int i = 0; i + 1 < s.na; i += 2) {
    const auto p = std::polar(modulus(rng), angle(rng));
    multiply(p);
    multiply(std::conj(p));
  }
  if (s.na % 2 == 1) multiply(modulus(rng) * (unit(rng) < 0 ? -1.0 : 1.0));
  Eigen::VectorXd a(s.na), b(s.nb);
  for (int i = 0; i < s.na; ++i) a(i) = c[std::size_t(i) + 1].real();
  for (int j = 0; j < s.nb; ++j) b(j) = magnitude(rng) * (unit(rng) < 0 ? -1.0 : 1.0);
  return ArxModel(s, a, b);
}

// White Gaussian input, white equation noise of standard deviation 0.1.
void simulate(const ArxModel& m, std::size_t n, std::mt19937_64& rng, std::vector<double>& u,
              std::vector<double>& y) {
  std::normal_distribution<double> normal(0.0, 1.0);
  u.resize(n);
  y.resize(n);
  for (auto& v : u) v = normal(rng);
  const auto& s = m.structure();
  for (std::size_t k = 0; k < n; ++k) {
    double sum = 0.1 * normal(rng);
    for (int i = 1; i <= s.na && std::size_t(i) <= k; ++i) sum -= m.a()(i - 1) * y[k - i];
    for (int j = 0; j < s.nb; ++j) {
      const long idx = long(k) - s.dead_time - j;
      if (idx >= 0) sum += m.b()(j) * u[std::size_t(idx)];
    }
    y[k] = sum;
  }
}

const std::vector<ArxStructure>& joint_structures() {
  static const std::vector<ArxStructure> s{{32, 32, 3}, {2, 2, 1}, {4, 3, 2},
                                           {6, 4, 0},   {3, 5, 4}, {8, 8, 2}};
  return s;
}

imscal::ident::OrderSelectionOptions sweep_options() {
  imscal::ident::OrderSelectionOptions options;
  options.grid = {1, 32, 1, 32, 0, 8};
  options.criterion = imscal::ident::OrderCriterion::kBic;
  options.validation_fraction = 0.3;
  return options;
}

std::vector<std::vector<double>> read_blocks(const std::string& file, std::size_t blocks) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + file);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t n = bytes.size() / sizeof(double) / blocks;
  if (n * sizeof(double) * blocks != bytes.size())
    throw std::runtime_error(file + ": size is not a multiple of " + std::to_string(blocks) +
                             " float64 blocks");
  std::vector<std::vector<double>> out(blocks, std::vector<double>(n));
  for (std::size_t b = 0; b < blocks; ++b)
    std::memcpy(out[b].data(), bytes.data() + b * n * sizeof(double), n * sizeof(double));
  return out;
}

void print_vector(const Eigen::VectorXd& v) {
  std::printf("[");
  for (Eigen::Index i = 0; i < v.size(); ++i) std::printf("%s%.17g", i ? ", " : "", v(i));
  std::printf("]");
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// CPU time of this process [s]: on a machine shared with other jobs the wall time overstates
// the cost, so both are reported.
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

int write_data(const std::string& file, std::size_t samples, std::size_t joints, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::string bytes;
  std::printf("{\"samples\": %zu, \"joints\": [", samples);
  for (std::size_t j = 0; j < joints; ++j) {
    const ArxStructure s = joint_structures()[j % joint_structures().size()];
    const ArxModel truth = random_system(s, rng);
    std::vector<double> u, y;
    simulate(truth, samples, rng, u, y);
    bytes.append(reinterpret_cast<const char*>(u.data()), u.size() * sizeof(double));
    bytes.append(reinterpret_cast<const char*>(y.data()), y.size() * sizeof(double));
    std::printf("%s{\"na\": %d, \"nb\": %d, \"d\": %d, \"theta\": ", j ? ", " : "", s.na, s.nb,
                s.dead_time);
    print_vector(truth.parameters());
    std::printf("}");
  }
  std::printf("]}\n");
  imscal::write_file_atomically(file, bytes);
  return 0;
}

int fit_file(const std::string& file, const ArxStructure& s) {
  const auto blocks = read_blocks(file, 2);
  const std::vector<IoSegment> data{{blocks[0], blocks[1]}};
  double best = 1e300, best_cpu = 1e300;
  imscal::ident::ArxFitResult* kept = nullptr;
  std::vector<imscal::ident::ArxFitResult> fits;
  fits.reserve(3);
  for (int r = 0; r < 3; ++r) {
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = cpu_seconds();
    fits.push_back(imscal::ident::fit_arx(data, s));
    best = std::min(best, seconds_since(start));
    best_cpu = std::min(best_cpu, cpu_seconds() - cpu_start);
    kept = &fits.back();
  }
  std::printf(
      "{\"fit_seconds\": %.6f, \"fit_cpu_seconds\": %.6f, \"method\": \"%s\", "
      "\"scaled_condition\": %.6g, \"rows\": %zu, \"theta\": ",
      best, best_cpu, imscal::ident::to_string(kept->method_used), kept->scaled_condition,
      kept->row_count);
  print_vector(kept->model.parameters());
  std::printf(", \"std\": ");
  print_vector(kept->parameter_std);
  std::printf("}\n");
  return 0;
}

int fit_multi_file(const std::string& file, const std::string& method, ArxStructure s) {
  using imscal::ident::LeastSquaresMethod;
  const auto blocks = read_blocks(file, 2 + std::size_t(s.extra_inputs));
  IoSegment data{blocks[0], blocks[1], {}, s.extra_inputs};
  for (int e = 0; e < s.extra_inputs; ++e) data.extra[std::size_t(e)] = blocks[2 + std::size_t(e)];
  imscal::ident::ArxFitOptions options;
  options.method = method == "qr"        ? LeastSquaresMethod::kQr
                   : method == "normal"  ? LeastSquaresMethod::kNormalEquations
                   : method == "refined" ? LeastSquaresMethod::kRefinedNormalEquations
                                         : LeastSquaresMethod::kAuto;
  const auto start = std::chrono::steady_clock::now();
  const auto fit = imscal::ident::fit_arx(std::vector<IoSegment>{data}, s, options);
  std::printf(
      "{\"fit_seconds\": %.6f, \"method\": \"%s\", \"refinement_steps\": %d, "
      "\"scaled_condition\": %.6g, \"rows\": %zu, \"rss\": %.17g, \"theta\": ",
      seconds_since(start), imscal::ident::to_string(fit.method_used), fit.refinement_steps,
      fit.scaled_condition, fit.row_count, fit.residual_sum_of_squares);
  print_vector(fit.model.parameters());
  std::printf(", \"std\": ");
  print_vector(fit.parameter_std);
  std::printf("}\n");
  return 0;
}

int identify_file(const std::string& file, std::size_t joints) {
  const auto blocks = read_blocks(file, 2 * joints);
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = cpu_seconds();
  double validation_seconds = 0.0;
  std::string report = "[";
  for (std::size_t j = 0; j < joints; ++j) {
    const std::vector<IoSegment> data{{blocks[2 * j], blocks[2 * j + 1]}};
    const auto result = imscal::ident::select_arx_order(data, sweep_options());
    // Validation statistics on the held-out last 30 % (what a report would show).
    const auto validation_start = std::chrono::steady_clock::now();
    const std::size_t n = blocks[2 * j].size(), cut = n - n * 3 / 10;
    const std::vector<IoSegment> held_out{
        {std::span<const double>(blocks[2 * j]).subspan(cut),
         std::span<const double>(blocks[2 * j + 1]).subspan(cut)}};
    const auto stats = imscal::ident::validate_arx(result.final_fit.model, held_out);
    validation_seconds += seconds_since(validation_start);
    char line[512];
    std::snprintf(line, sizeof line,
                  "%s{\"joint\": %zu, \"na\": %d, \"nb\": %d, \"d\": %d, \"method\": \"%s\", "
                  "\"one_step_fit_percent\": %.4f, \"simulation_fit_percent\": %.4f, "
                  "\"white\": %s, \"white_outside\": %d, \"white_max_over_band\": %.3f, "
                  "\"independent\": %s, \"stable\": %s}",
                  j ? ", " : "", j, result.chosen.na, result.chosen.nb, result.chosen.dead_time,
                  imscal::ident::to_string(result.final_fit.method_used),
                  stats.one_step_fit_percent, stats.simulation_fit_percent,
                  stats.residual_whiteness.passed ? "true" : "false",
                  stats.residual_whiteness.outside_count,
                  stats.residual_whiteness.max_abs_correlation / stats.residual_whiteness.band,
                  stats.input_residual.passed ? "true" : "false",
                  result.final_fit.model.is_stable() ? "true" : "false");
    report += line;
  }
  const double total = seconds_since(start);
  const double total_cpu = cpu_seconds() - cpu_start;
  std::printf(
      "{\"total_seconds\": %.6f, \"total_cpu_seconds\": %.6f, \"validation_seconds\": %.6f, "
      "\"joints\": %s]}\n",
      total, total_cpu, validation_seconds, report.c_str());
  return 0;
}

// Benchmark data: the order-32 system, 1 M samples, made once.
const std::vector<std::vector<double>>& bench_data() {
  static const auto data = [] {
    std::mt19937_64 rng(42);
    const ArxModel truth = random_system({32, 32, 3}, rng);
    std::vector<std::vector<double>> d(2);
    simulate(truth, 1'000'000, rng, d[0], d[1]);
    return d;
  }();
  return data;
}

void BM_ArxFitOrder32(benchmark::State& state) {
  const auto& d = bench_data();
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const std::vector<IoSegment> data{
      {std::span<const double>(d[0]).first(n), std::span<const double>(d[1]).first(n)}};
  for (auto _ : state) benchmark::DoNotOptimize(imscal::ident::fit_arx(data, {32, 32, 3}));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_ArxFitOrder32)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond);

void BM_ArxFitOrder32Qr(benchmark::State& state) {
  const auto& d = bench_data();
  const std::vector<IoSegment> data{{d[0], d[1]}};
  imscal::ident::ArxFitOptions options;
  options.method = imscal::ident::LeastSquaresMethod::kQr;
  for (auto _ : state) benchmark::DoNotOptimize(imscal::ident::fit_arx(data, {32, 32, 3}, options));
}
BENCHMARK(BM_ArxFitOrder32Qr)->Unit(benchmark::kMillisecond);

void BM_OrderSweep(benchmark::State& state) {
  const auto& d = bench_data();
  const std::vector<IoSegment> data{{d[0], d[1]}};
  for (auto _ : state)
    benchmark::DoNotOptimize(imscal::ident::select_arx_order(data, sweep_options()));
  state.counters["candidates"] = 32 * 32 * 9;
}
BENCHMARK(BM_OrderSweep)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "--write-data" && argc == 6)
      return write_data(argv[2], std::stoul(argv[3]), std::stoul(argv[4]),
                        static_cast<unsigned>(std::stoul(argv[5])));
    if (mode == "--fit" && argc == 6)
      return fit_file(argv[2], {std::stoi(argv[3]), std::stoi(argv[4]), std::stoi(argv[5])});
    if (mode == "--identify" && argc == 4) return identify_file(argv[2], std::stoul(argv[3]));
    if (mode == "--fit-multi" && argc >= 8 && argc <= 7 + imscal::ident::kMaxExtraInputs) {
      ArxStructure s{std::stoi(argv[4]), std::stoi(argv[5]), std::stoi(argv[6]), argc - 7, {}};
      for (int e = 0; e < s.extra_inputs; ++e) s.nx[std::size_t(e)] = std::stoi(argv[7 + e]);
      return fit_multi_file(argv[2], argv[3], s);
    }
    if (mode.rfind("--write-data", 0) == 0 || mode == "--fit" || mode == "--identify" ||
        mode == "--fit-multi") {
      std::fprintf(stderr, "usage: see the comment at the top of bench/bench_arx.cpp\n");
      return 2;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_arx: %s\n", e.what());
    return 1;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
