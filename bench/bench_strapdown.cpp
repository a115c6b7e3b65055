// Throughput of the strapdown mechanization: one hour of 2 kHz increments (7.2 million samples),
// single-threaded. Goal: >= 20 million samples/s (50 ns per sample).
//   build-*/bench/bench_strapdown  -> counter "samples_per_s"
// The data are robot-like increments (rates up to ~3 rad/s about a wandering axis, gravity and
// an oscillating acceleration in the specific force), made by a cheap closed form: only their
// magnitudes matter here, not their consistency.
#include <benchmark/benchmark.h>

#include <cmath>

#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"
#include "ims/strapdown.hpp"

namespace ims = imscal::ims;

namespace {

constexpr double kRateHz = 2000.0;
constexpr std::size_t kSampleCount = 7'200'000;  // 1 h at 2 kHz

const ims::ImuSeries& hour_of_increments() {
  static const ims::ImuSeries series = [] {
    ims::ImuSeries s;
    s.quantity = ims::ImuQuantity::kIncrements;
    s.nominal_dt_s = 1.0 / kRateHz;
    s.samples.resize(kSampleCount);
    const double h = s.nominal_dt_s;
    for (std::size_t k = 0; k < kSampleCount; ++k) {
      const double t = static_cast<double>(k + 1) * h;
      ims::ImuSample& sample = s.samples[k];
      sample.t_s = t;
      sample.gyro = h * Eigen::Vector3d(2.0 * std::sin(0.7 * t), 1.5 * std::cos(0.3 * t),
                                        3.0 * std::sin(0.11 * t) * std::cos(1.3 * t));
      sample.acc = h * Eigen::Vector3d(9.81 * std::sin(0.05 * t) + 1.5 * std::sin(2.0 * t),
                                       0.8 * std::cos(1.7 * t), 9.81 * std::cos(0.05 * t));
    }
    return s;
  }();
  return series;
}

void BM_StrapdownHourAt2kHz(benchmark::State& state) {
  const ims::EarthModel earth(ims::Site{48.7, 9.1, 380.0});
  const ims::ImuSeries& series = hour_of_increments();
  for (auto _ : state) {
    ims::Strapdown strapdown(earth, ims::NavState{0.0});
    for (const ims::ImuSample& sample : series.samples) strapdown.step(sample);
    benchmark::DoNotOptimize(strapdown.state());
  }
  state.counters["samples_per_s"] = benchmark::Counter(
      static_cast<double>(series.samples.size()) * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
  state.counters["ns_per_sample"] = benchmark::Counter(
      static_cast<double>(series.samples.size()) * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(BM_StrapdownHourAt2kHz)->Unit(benchmark::kMillisecond)->MinTime(2.0);

BENCHMARK_MAIN();
