// Bad IMS files and the checks of ims/imu_validation: every file in
// tests/data/bad_inputs/imu/ must be refused with an InputError that names the file, the line
// and the field its NAME.expected states, and says what its "contains:" line says. Generated
// series check the statistics (median step, jitter, gaps, saturation counts) against the
// values they were built with, and the gravity check against Somigliana's closed form.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "core/input_error.hpp"
#include "ims/imu_csv.hpp"
#include "ims/imu_file.hpp"
#include "ims/imu_validation.hpp"
#include "tests/support/text_file.hpp"

namespace fs = std::filesystem;
using imscal::InputError;
using imscal::ims::ImuQuantity;
using imscal::ims::ImuReadOptions;
using imscal::ims::ImuReadReport;
using imscal::ims::ImuSample;
using imscal::ims::ImuSeries;
using imscal::ims::Site;
using imscal::ims::validate_imu_series;
using imscal::test_support::read_text;

namespace {

const fs::path kBadDir = fs::path(IMSCAL_TEST_DATA_DIR) / "bad_inputs" / "imu";

// The bad files, one per check (see the comment line of each NAME.expected).
const char* const kBadCases[] = {
    "empty",
    "not_imscal",
    "bad_header_line",
    "missing_quantity",
    "bad_quantity",
    "bad_nominal_dt",
    "duplicate_header_key",
    "site_incomplete",
    "column_quantity_mismatch",
    "unknown_unit",
    "missing_column",
    "no_data",
    "truncated_last_line",
    "wrong_column_count",
    "too_many_fields",
    "non_numeric",
    "malformed_number",
    "empty_field",
    "empty_line",
    "nan_value",
    "inf_value",
    "duplicate_time",
    "backwards_time",
    "gap",
    "nominal_dt_mismatch",
    "saturated_gyro",
    "saturated_acc_increments",
    "acc_in_g",
    "acc_in_mg",
    "increments_holding_rates",
    "gyro_in_deg_s",
    "byte_order_mark_bad_quantity",
};

struct Expected {
  std::size_t line = 0;
  std::string field;
  std::string contains;
};

Expected load_expected(const fs::path& file) {
  std::ifstream in(file);
  EXPECT_TRUE(in) << file;
  Expected e;
  std::string text;
  while (std::getline(in, text)) {
    if (text.starts_with("line: ")) e.line = std::stoul(text.substr(6));
    if (text.starts_with("field: ")) e.field = text.substr(7);
    if (text.starts_with("contains: ")) e.contains = text.substr(10);
  }
  return e;
}

class BadImuFile : public testing::TestWithParam<const char*> {};

TEST_P(BadImuFile, RefusedWithFileLineAndField) {
  const fs::path file = kBadDir / (std::string(GetParam()) + ".csv");
  const Expected expected = load_expected(kBadDir / (std::string(GetParam()) + ".expected"));
  ASSERT_FALSE(expected.contains.empty());
  const std::string before = read_text(file);
  // The same refusal with the samples read into a temporary file (as calibrate reads).
  for (const bool samples_to_file : {false, true}) {
    ImuReadOptions options;
    options.samples_to_file = samples_to_file;
    try {
      imscal::ims::read_imu_csv(file, options);
      FAIL() << file << " was accepted, samples_to_file " << samples_to_file;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(e.file(), file.string());
      EXPECT_EQ(e.line(), expected.line) << message;
      EXPECT_EQ(e.field(), expected.field) << message;
      EXPECT_NE(message.find(file.string() + ":" + std::to_string(expected.line) + ": field '" +
                             expected.field + "'"),
                std::string::npos)
          << message;
      EXPECT_NE(message.find(expected.contains), std::string::npos) << message;
    }
  }
  // Readers never modify their input.
  EXPECT_EQ(read_text(file), before);
  // A conversion (read, then write) of the bad file leaves no output and no temporary behind.
  const fs::path out_dir =
      fs::temp_directory_path() / fmt::format("imscal-test-bad-imu-{}-{}", ::getpid(), GetParam());
  fs::remove_all(out_dir);
  fs::create_directories(out_dir);
  EXPECT_THROW(
      imscal::ims::write_imu_file(out_dir / "converted.imsb", imscal::ims::read_imu_file(file),
                                  imscal::Overwrite::kRefuse),
      InputError);
  EXPECT_TRUE(fs::is_empty(out_dir));
  fs::remove_all(out_dir);
}

INSTANTIATE_TEST_SUITE_P(ImuValidation, BadImuFile, testing::ValuesIn(kBadCases),
                         [](const testing::TestParamInfo<const char*>& info) {
                           return std::string(info.param);
                         });

TEST(ImuValidation, EveryBadFileIsListedAndHasItsExpectation) {
  std::set<std::string> listed(std::begin(kBadCases), std::end(kBadCases));
  std::set<std::string> found;
  for (const auto& entry : fs::directory_iterator(kBadDir)) {
    const fs::path p = entry.path();
    if (p.extension() == ".csv") {
      found.insert(p.stem().string());
      EXPECT_TRUE(fs::exists(fs::path(p).replace_extension(".expected"))) << p;
    }
  }
  EXPECT_EQ(found, listed);
}

// ---------------------------------------------------------------------------------------------
// Generated series.

// A rates record at rest: gravity along z plus small deterministic ripple.
ImuSeries rest_series(std::size_t n, double dt, double gravity_m_s2) {
  ImuSeries s;
  s.quantity = ImuQuantity::kRates;
  s.nominal_dt_s = dt;
  s.source = "generated.imsb";
  for (std::size_t i = 0; i < n; ++i) {
    const double k = static_cast<double>(i);
    s.samples.push_back(ImuSample{(k + 1) * dt, Eigen::Vector3d(1e-5 * std::sin(k), 0, 0),
                                  Eigen::Vector3d(0, 1e-3 * std::cos(k), gravity_m_s2)});
  }
  return s;
}

// A UTF-8 byte-order mark (some editors write one) is skipped with a warning: the record reads as
// the same file without it, sample for sample.
// A file that is not an imscal CSV is refused from its first byte, before the reader maps and
// pages in the rest: a sparse file of 8 GiB is refused at once (paging it in would take minutes).
TEST(ImuValidation, HugeForeignFileIsRefusedFromItsFirstLine) {
  const fs::path file =
      fs::temp_directory_path() / fmt::format("imscal-test-imu-sparse-{}.csv", ::getpid());
  { std::ofstream(file, std::ios::binary) << ""; }
  fs::resize_file(file, std::uintmax_t{8} << 30);  // zeros, no disk blocks
  const auto start = std::chrono::steady_clock::now();
  try {
    imscal::ims::read_imu_csv(file);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 1u) << e.what();
    EXPECT_NE(std::string(e.what()).find("not an imscal IMU CSV file"), std::string::npos)
        << e.what();
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fs::remove(file);
  EXPECT_LT(seconds, 1.0);
}

TEST(ImuValidation, ByteOrderMarkIsSkippedWithAWarning) {
  const ImuSeries series = rest_series(200, 0.01, 9.80665);
  const fs::path folder =
      fs::temp_directory_path() / fmt::format("imscal-test-imu-bom-{}", ::getpid());
  fs::create_directories(folder);
  const std::string text = imscal::ims::format_imu_csv(series);
  std::ofstream(folder / "plain.csv", std::ios::binary) << text;
  std::ofstream(folder / "marked.csv", std::ios::binary) << "\xEF\xBB\xBF" << text;
  ImuReadReport report;
  const ImuSeries plain = imscal::ims::read_imu_csv(folder / "plain.csv");
  const ImuSeries marked = imscal::ims::read_imu_csv(folder / "marked.csv", {}, &report);
  fs::remove_all(folder);
  ASSERT_EQ(marked.samples.size(), plain.samples.size());
  for (std::size_t i = 0; i < plain.samples.size(); ++i) {
    EXPECT_EQ(marked.samples[i].t_s, plain.samples[i].t_s);
    EXPECT_EQ(marked.samples[i].gyro, plain.samples[i].gyro);
    EXPECT_EQ(marked.samples[i].acc, plain.samples[i].acc);
  }
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_NE(report.warnings.front().find("byte-order mark"), std::string::npos);
}

TEST(ImuValidation, StatisticsOfAJitteredRecord) {
  // Every 10th step is 30% long, every 10th (offset 5) 30% short; the rest exact. Jitter limit
  // 10%: 2 of every 10 steps count.
  const double dt = 0.01;
  ImuSeries s = rest_series(1001, dt, 9.80665);
  double t = 0.0;
  std::size_t expected_jitter = 0;
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    double step = dt;
    if (i > 0 && i % 10 == 0) step = 1.3 * dt;
    if (i % 10 == 5) step = 0.7 * dt;
    if (i > 0 && step != dt) ++expected_jitter;
    if (i > 0) sum_sq += (step - dt) * (step - dt);
    t += step;
    s.samples[i].t_s = t;
  }
  ImuReadReport report;
  validate_imu_series(s, ImuReadOptions{}, &report);
  EXPECT_EQ(report.samples, 1001u);
  EXPECT_EQ(report.jitter_count, expected_jitter);
  // Steps are differences of accumulated sums: a few ulp of t (~1e-15 s) off the built value.
  EXPECT_NEAR(report.median_dt_s, dt, 1e-12);
  EXPECT_NEAR(report.jitter_max_abs_s, 0.3 * dt, 1e-12);
  EXPECT_NEAR(report.jitter_rms_s, std::sqrt(sum_sq / 1000.0), 1e-12);
  EXPECT_NEAR(report.max_step_s, 1.3 * dt, 1e-12);
  EXPECT_NEAR(report.duration_s, s.samples.back().t_s - s.samples.front().t_s, 0.0);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find(fmt::format("{} of 1000 steps", expected_jitter)),
            std::string::npos)
      << report.warnings[0];
  EXPECT_NE(report.warnings[0].find("RMS deviation"), std::string::npos) << report.warnings[0];
  EXPECT_NE(report.brief().find("1001 samples"), std::string::npos);
}

TEST(ImuValidation, GapsAreErrorsOrCountedWarnings) {
  ImuSeries s = rest_series(200, 0.01, 9.80665);
  for (std::size_t i = 100; i < s.samples.size(); ++i) s.samples[i].t_s += 0.02;  // 2 missing
  for (std::size_t i = 150; i < s.samples.size(); ++i) s.samples[i].t_s += 0.01;  // 1 missing
  try {
    validate_imu_series(s, ImuReadOptions{});
    FAIL() << "gap accepted";
  } catch (const InputError& e) {
    // Binary-like source (first_data_line 0): the record number is in the message.
    EXPECT_EQ(e.line(), 0u);
    EXPECT_EQ(e.field(), "t_s");
    EXPECT_NE(std::string(e.what()).find("record 101 of 200"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("3 nominal intervals"), std::string::npos) << e.what();
  }
  ImuReadOptions options;
  options.allow_gaps = true;
  ImuReadReport report;
  validate_imu_series(s, options, &report);
  EXPECT_EQ(report.gap_count, 2u);
  EXPECT_NEAR(report.max_step_s, 0.03, 1e-12);  // ulp-level error of the built stamps
  // A wider gap factor accepts a 3-interval step as regular (but jittered).
  options = ImuReadOptions{};
  options.gap_factor = 3.5;
  validate_imu_series(s, options, &report);
  EXPECT_EQ(report.gap_count, 0u);
  EXPECT_EQ(report.jitter_count, 2u);
}

TEST(ImuValidation, SaturationErrorOrCountedWarning) {
  ImuSeries s = rest_series(200, 0.01, 9.80665);
  s.samples[120].acc.x() = -196.133;  // exactly at the default 20 g range: saturated
  s.samples[130].gyro.y() = 20.0;
  s.samples[131].gyro.y() = 17.0;  // below the default 1000 deg/s = 17.45 rad/s
  try {
    validate_imu_series(s, ImuReadOptions{});
    FAIL() << "saturation accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "acc_x_m_s2");
    EXPECT_NE(std::string(e.what()).find("record 121 of 200"), std::string::npos) << e.what();
  }
  ImuReadOptions options;
  options.allow_saturation = true;
  ImuReadReport report;
  validate_imu_series(s, options, &report);
  EXPECT_EQ(report.saturated_count, 2u);
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_NE(report.warnings.back().find("2 saturated values"), std::string::npos);
  EXPECT_NE(report.warnings.back().find("field 'acc_x_m_s2'"), std::string::npos);
  options.gyro_range_rad_s = 16.0;  // now 17 rad/s saturates too
  validate_imu_series(s, options, &report);
  EXPECT_EQ(report.saturated_count, 3u);
}

// Somigliana's closed form for normal gravity on the ellipsoid (WGS84, NIMA TR8350.2).
double somigliana(double latitude_deg) {
  const double s2 = std::pow(std::sin(latitude_deg * M_PI / 180.0), 2);
  return 9.7803253359 * (1 + 0.00193185265241 * s2) / std::sqrt(1 - 6.69437999014e-3 * s2);
}

TEST(ImuValidation, StaticGravityAgainstTheSiteOrTheDefault) {
  const double g_equator = somigliana(0.0);  // 9.7803 m/s^2
  ImuReadOptions options;
  ImuReadReport report;
  // With the site: tolerance 0.2 m/s^2 about the local normal gravity.
  ImuSeries s = rest_series(300, 0.01, g_equator + 0.15);
  s.site = Site{0.0, 10.0, 0.0};
  validate_imu_series(s, options, &report);
  // The ripple (1e-3 m/s^2 on y) changes |f| by ~1e-7 m/s^2 only.
  EXPECT_NEAR(*report.static_specific_force_m_s2, g_equator + 0.15, 1e-6);
  EXPECT_NEAR(*report.expected_gravity_m_s2, g_equator, 1e-6);  // EarthModel vs closed form
  EXPECT_EQ(report.static_windows, 6u);                         // 3 s in 0.5 s windows
  s = rest_series(300, 0.01, g_equator + 0.25);
  s.site = Site{0.0, 10.0, 0.0};
  EXPECT_THROW(validate_imu_series(s, options), InputError);
  // Without a site: 9.80665 with 0.25 m/s^2: 9.80665 - 0.24 passes, - 0.26 does not.
  s = rest_series(300, 0.01, 9.80665 - 0.24);
  validate_imu_series(s, options, &report);
  EXPECT_DOUBLE_EQ(*report.expected_gravity_m_s2, 9.80665);
  s = rest_series(300, 0.01, 9.80665 - 0.26);
  try {
    validate_imu_series(s, options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("default gravity, the file has no site"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("check the accelerometer units"), std::string::npos);
  }
  // Units off by the usual factors are named.
  s = rest_series(300, 0.01, 9.80665 * 1000.0);
  try {
    validate_imu_series(s, options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mm/s^2, not m/s^2"), std::string::npos) << e.what();
  }
  // check_units = false turns the check off.
  s = rest_series(300, 0.01, 9.80665 - 0.26);
  options.check_units = false;
  EXPECT_NO_THROW(validate_imu_series(s, options, &report));
  EXPECT_FALSE(report.static_specific_force_m_s2.has_value());
}

TEST(ImuValidation, NoRestWindowIsAWarning) {
  ImuSeries s = rest_series(300, 0.01, 9.80665);
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    s.samples[i].gyro.z() = 2.0 * std::sin(0.1 * static_cast<double>(i));  // always turning
  }
  ImuReadReport report;
  validate_imu_series(s, ImuReadOptions{}, &report);
  EXPECT_EQ(report.static_windows, 0u);
  EXPECT_FALSE(report.static_specific_force_m_s2.has_value());
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("no rest window"), std::string::npos);
}

TEST(ImuValidation, ShortFastTurnsAreNotDegrees) {
  // 40 rad/s for 0.1 s is below the 0.2 s a deg/s record would sustain: accepted as a spike
  // (with saturation allowed, since 40 rad/s is beyond the default gyro range).
  ImuSeries s = rest_series(300, 0.01, 9.80665);
  for (std::size_t i = 200; i < 210; ++i) s.samples[i].gyro.x() = 40.0;
  ImuReadOptions options;
  options.allow_saturation = true;
  ImuReadReport report;
  EXPECT_NO_THROW(validate_imu_series(s, options, &report));
  EXPECT_EQ(report.saturated_count, 10u);
  for (std::size_t i = 210; i < 225; ++i) s.samples[i].gyro.x() = 40.0;  // now 0.25 s
  try {
    validate_imu_series(s, options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "gyro_x_rad_s");
    EXPECT_NE(std::string(e.what()).find("record 201 of 300"), std::string::npos) << e.what();
  }
}

TEST(ImuValidation, SiColumnNames) {
  EXPECT_EQ(imscal::ims::si_column_names(ImuQuantity::kRates)[4], "acc_x_m_s2");
  EXPECT_EQ(imscal::ims::si_column_names(ImuQuantity::kIncrements)[3], "dtheta_z_rad");
}

}  // namespace
