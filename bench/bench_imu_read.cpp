// Read throughput of the raw IMS file forms: one hour of increments at 2 kHz (7.2 M samples, the
// goal is >= 200 MB/s for CSV) and the same record in the binary form (goal: >= 5x faster than
// CSV). Both readers run their full validation. Counters: bytes_per_second (MB/s of file read)
// and, for binary, speedup_vs_csv measured in the same run (CPU time of the reading thread, as
// Google Benchmark's own figures; speedup_vs_csv_wall in wall-clock time).
//
// The files are written once into $IMSCAL_BENCH_DIR (default: the system temporary folder) and
// removed at exit. IMSCAL_BENCH_IMU_SECONDS shortens the record (default 3600 s).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <random>
#include <string>

#include "ims/imu_binary.hpp"
#include "ims/imu_csv.hpp"

namespace fs = std::filesystem;
using imscal::ims::ImuQuantity;
using imscal::ims::ImuSample;
using imscal::ims::ImuSeries;

namespace {

constexpr double kRate_hz = 2000.0;

// A ring-laser-gyro/servo-accelerometer record: 10 s at rest, then a robot-like motion; random
// noise makes every value need its full 17 significant digits, the worst case for text.
ImuSeries make_record(double seconds) {
  const double dt = 1.0 / kRate_hz;
  const auto n = static_cast<std::size_t>(seconds * kRate_hz);
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, 1.0);
  ImuSeries s;
  s.quantity = ImuQuantity::kIncrements;
  s.nominal_dt_s = dt;
  s.site = imscal::ims::Site{48.78, 9.18, 245.0};
  s.metadata = {{"sensor", "benchmark"}};
  s.samples.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i + 1) * dt;
    const double moving = t > 10.0 ? 1.0 : 0.0;
    const Eigen::Vector3d omega =
        moving * Eigen::Vector3d(0.8 * std::sin(1.3 * t), 0.5 * std::cos(0.7 * t), 0.2) +
        2e-5 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    const Eigen::Vector3d f =
        moving * Eigen::Vector3d(1.5 * std::sin(2.1 * t), 1.0 * std::cos(1.1 * t), 0.5) +
        Eigen::Vector3d(0.0, 0.0, 9.809) +
        2e-3 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    s.samples.push_back(ImuSample{t, omega * dt, f * dt});
  }
  return s;
}

struct PerRead {
  double cpu_s = 0.0, wall_s = 0.0;  // per read
};

struct Files {
  fs::path dir, csv, binary;
  PerRead csv_per_read;  // from the CSV benchmark, for the ratio
  Files() {
    const char* base = std::getenv("IMSCAL_BENCH_DIR");
    const char* seconds = std::getenv("IMSCAL_BENCH_IMU_SECONDS");
    dir = (base != nullptr ? fs::path(base) : fs::temp_directory_path()) /
          ("imscal-bench-imu-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    csv = dir / "record.csv";
    binary = dir / "record.imsb";
    const ImuSeries record = make_record(seconds != nullptr ? std::atof(seconds) : 3600.0);
    imscal::ims::write_imu_csv(csv, record, imscal::Overwrite::kAllow);
    imscal::ims::write_imu_binary(binary, record, imscal::Overwrite::kAllow);
  }
  ~Files() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
};

Files& files() {
  static Files instance;
  return instance;
}

double thread_cpu_seconds() {
  timespec now{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

// Times the reads both in CPU time of this thread (what Google Benchmark reports by default,
// robust on a shared machine) and in wall-clock time.
template <typename Read>
PerRead run(benchmark::State& state, const fs::path& file, Read read) {
  const auto start = std::chrono::steady_clock::now();
  const double start_cpu = thread_cpu_seconds();
  std::size_t samples = 0;
  for (auto _ : state) {
    ImuSeries series = read(file);
    samples = series.samples.size();
    benchmark::DoNotOptimize(series.samples.data());
  }
  const double cpu = thread_cpu_seconds() - start_cpu;
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
  const auto file_bytes = static_cast<std::int64_t>(fs::file_size(file));
  state.SetBytesProcessed(state.iterations() * file_bytes);
  state.counters["samples"] = static_cast<double>(samples);
  state.counters["file_MB"] = static_cast<double>(file_bytes) / 1e6;
  const auto n = static_cast<double>(state.iterations());
  return {cpu / n, elapsed.count() / n};
}

void BM_ReadImuCsv(benchmark::State& state) {
  Files& f = files();
  f.csv_per_read =
      run(state, f.csv, [](const fs::path& p) { return imscal::ims::read_imu_csv(p); });
}

void BM_ReadImuBinary(benchmark::State& state) {
  Files& f = files();
  const PerRead binary =
      run(state, f.binary, [](const fs::path& p) { return imscal::ims::read_imu_binary(p); });
  if (f.csv_per_read.cpu_s > 0.0) {
    state.counters["speedup_vs_csv"] = f.csv_per_read.cpu_s / binary.cpu_s;
    state.counters["speedup_vs_csv_wall"] = f.csv_per_read.wall_s / binary.wall_s;
  }
}

}  // namespace

// The CSV benchmark must run first: the binary one reports its speed-up against it.
BENCHMARK(BM_ReadImuCsv)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_ReadImuBinary)->Unit(benchmark::kMillisecond)->Iterations(10);

BENCHMARK_MAIN();
