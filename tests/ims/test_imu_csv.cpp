// The project's IMU CSV form: bit-exact write/read round trips (the writer prints the shortest
// representation that reads back to the same double), the line of every sample, unit-suffixed
// columns converted to SI against closed forms (1 g = 9.80665 m/s^2 by definition,
// 1 deg = pi/180 rad), and writes that leave nothing behind when they fail.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "ims/imu_csv.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace fs = std::filesystem;
using imscal::InputError;
using imscal::Overwrite;
using imscal::ims::ImuQuantity;
using imscal::ims::ImuReadOptions;
using imscal::ims::ImuReadReport;
using imscal::ims::ImuSample;
using imscal::ims::ImuSeries;
using imscal::ims::read_imu_csv;
using imscal::ims::Site;
using imscal::ims::write_imu_csv;
using imscal::test_support::read_text;
using imscal::test_support::write_text;

namespace {

class ImuCsv : public imscal::test_support::ScratchDirTest {};

// A record of n samples: 1 s at rest, then a turning and accelerating motion, with random
// noise so that every value needs all 17 significant digits.
ImuSeries make_series(std::size_t n, double dt, ImuQuantity quantity, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  ImuSeries s;
  s.quantity = quantity;
  s.nominal_dt_s = dt;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i + 1) * dt;
    const double moving = t > 1.0 ? 1.0 : 0.0;
    Eigen::Vector3d omega(0.8 * std::sin(3.0 * t), 0.5 * std::cos(2.0 * t), -0.3);
    Eigen::Vector3d f(2.0 * std::sin(5.0 * t), -1.5 * std::cos(4.0 * t), 1.0);
    omega = moving * omega + 1e-4 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    f = moving * f + Eigen::Vector3d(0.01, -0.02, 9.80665) +
        1e-3 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    const double scale = quantity == ImuQuantity::kIncrements ? dt : 1.0;
    s.samples.push_back(ImuSample{t, omega * scale, f * scale});
  }
  return s;
}

std::uint64_t bits(double v) {
  return std::bit_cast<std::uint64_t>(v);
}

void expect_bit_identical(const ImuSeries& a, const ImuSeries& b) {
  ASSERT_EQ(a.samples.size(), b.samples.size());
  EXPECT_EQ(a.quantity, b.quantity);
  EXPECT_EQ(bits(a.nominal_dt_s), bits(b.nominal_dt_s));
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    const ImuSample& x = a.samples[i];
    const ImuSample& y = b.samples[i];
    ASSERT_EQ(bits(x.t_s), bits(y.t_s)) << "sample " << i;
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(bits(x.gyro[k]), bits(y.gyro[k])) << "sample " << i << " axis " << k;
      ASSERT_EQ(bits(x.acc[k]), bits(y.acc[k])) << "sample " << i << " axis " << k;
    }
  }
}

std::vector<std::string> lines_of(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

TEST_F(ImuCsv, RoundTripIsBitExactForBothQuantities) {
  for (ImuQuantity q : {ImuQuantity::kRates, ImuQuantity::kIncrements}) {
    ImuSeries s = make_series(3000, 0.001, q, 7);
    s.site = Site{48.78232, 9.18162, 245.4};
    s.metadata = {{"sensor", "iMAR iNAV-RQH"}, {"serial", "0815"}, {"note", "a: b, c"}};
    const fs::path file = dir_ / "record.csv";
    write_imu_csv(file, s, Overwrite::kAllow);
    ImuReadReport report;
    const ImuSeries r = read_imu_csv(file, ImuReadOptions{}, &report);
    expect_bit_identical(s, r);
    ASSERT_TRUE(r.site.has_value());
    EXPECT_EQ(bits(r.site->latitude_deg), bits(s.site->latitude_deg));
    EXPECT_EQ(bits(r.site->longitude_deg), bits(s.site->longitude_deg));
    EXPECT_EQ(bits(r.site->height_m), bits(s.site->height_m));
    EXPECT_EQ(r.metadata, s.metadata);
    EXPECT_EQ(r.source, file.string());
    // 3 required + 3 site + 3 metadata header lines, the column line, then data.
    EXPECT_EQ(r.first_data_line, 11u);
    EXPECT_EQ(report.samples, 3000u);
    EXPECT_TRUE(report.warnings.empty()) << report.brief();
    EXPECT_GE(report.static_windows, 2u);  // the first second is at rest
  }
}

// Read into a temporary file (as calibrate reads a long record), the samples are the written
// ones bit for bit and live in the file.
TEST_F(ImuCsv, RoundTripIntoATemporaryFileIsBitExact) {
  for (ImuQuantity q : {ImuQuantity::kRates, ImuQuantity::kIncrements}) {
    const ImuSeries s = make_series(30000, 0.0005, q, 11);
    const fs::path file = dir_ / "record.csv";
    write_imu_csv(file, s, Overwrite::kAllow);
    ImuReadOptions options;
    options.samples_to_file = true;
    const ImuSeries r = read_imu_csv(file, options);
    EXPECT_TRUE(r.samples.on_file());
    expect_bit_identical(s, r);
  }
}

TEST_F(ImuCsv, RoundTripKeepsExtremeDoubles) {
  ImuSeries s = make_series(20, 0.01, ImuQuantity::kRates, 3);
  s.samples[3].gyro = Eigen::Vector3d(-0.0, std::numeric_limits<double>::denorm_min(),
                                      std::numeric_limits<double>::min());
  s.samples[4].acc = Eigen::Vector3d(1e300, -std::numeric_limits<double>::max(), 0.1 + 0.2);
  s.samples[5].t_s = std::nextafter(s.samples[5].t_s, 1.0);
  const fs::path file = dir_ / "extreme.csv";
  write_imu_csv(file, s, Overwrite::kAllow);
  ImuReadOptions options;  // the extremes are far beyond any sensor range
  options.allow_saturation = true;
  options.check_units = false;
  expect_bit_identical(s, read_imu_csv(file, options));
  EXPECT_TRUE(std::signbit(read_imu_csv(file, options).samples[3].gyro.x()));
}

TEST_F(ImuCsv, SampleIIsOnLineFirstDataLinePlusI) {
  const ImuSeries s = make_series(50, 0.01, ImuQuantity::kIncrements, 11);
  const fs::path file = dir_ / "lines.csv";
  write_imu_csv(file, s, Overwrite::kAllow);
  const ImuSeries r = read_imu_csv(file);
  const std::vector<std::string> lines = lines_of(file);
  for (std::size_t i = 0; i < r.samples.size(); ++i) {
    const std::string& line = lines.at(r.first_data_line + i - 1);  // lines are 1-based
    const double t = std::stod(line.substr(0, line.find(',')));
    EXPECT_EQ(t, r.samples[i].t_s) << "line " << r.first_data_line + i;
  }
}

TEST_F(ImuCsv, UnitSuffixedColumnsAreConvertedToSiWithAWarning) {
  const fs::path file = dir_ / "units.csv";
  write_text(file,
             "# imscal-imu: 1\n# quantity: rates\n# nominal_dt_s: 0.5\n"
             "t_ms,gyro_x_deg_s,gyro_y_deg_s,gyro_z_deg_h,acc_x_g,acc_y_mg,acc_z_g\n"
             "500,180,-90,3600,0.5,-250,1\n"
             "1000,180,-90,3600,0.5,-250,1\n");
  ImuReadOptions options;
  options.check_units = false;  // two samples cannot show rest; only the conversion is tested
  ImuReadReport report;
  const ImuSeries r = read_imu_csv(file, options, &report);
  ASSERT_EQ(r.samples.size(), 2u);
  const ImuSample& s = r.samples[1];
  // Each value is one product with a constant rounded to double: within 1 ulp of the closed form.
  EXPECT_DOUBLE_EQ(s.t_s, 1.0);
  EXPECT_DOUBLE_EQ(s.gyro.x(), M_PI);
  EXPECT_DOUBLE_EQ(s.gyro.y(), -M_PI / 2.0);
  EXPECT_DOUBLE_EQ(s.gyro.z(), M_PI / 180.0);  // 3600 deg/h = 1 deg/s
  EXPECT_EQ(s.acc.z(), 9.80665);               // 1 g: the factor itself, exactly
  EXPECT_DOUBLE_EQ(s.acc.x(), 9.80665 / 2.0);
  EXPECT_DOUBLE_EQ(s.acc.y(), -9.80665 / 4.0);
  const std::string all = fmt::format("{}", fmt::join(report.warnings, "\n"));
  EXPECT_NE(all.find("gyro_x_deg_s, gyro_y_deg_s in deg/s converted to rad/s"), std::string::npos)
      << all;
  EXPECT_NE(all.find("acc_x_g, acc_z_g in g converted to m/s^2 (x 9.80665)"), std::string::npos)
      << all;
  EXPECT_NE(all.find("acc_y_mg in mg converted to m/s^2"), std::string::npos) << all;
  EXPECT_NE(all.find("t_ms in ms converted to s"), std::string::npos) << all;
}

TEST_F(ImuCsv, IncrementColumnsInOtherUnits) {
  const fs::path file = dir_ / "increments.csv";
  write_text(file,
             "# imscal-imu: 1\n# quantity: increments\n# nominal_dt_s: 0.01\n"
             "t_s,dtheta_x_deg,dtheta_y_arcsec,dtheta_z_mrad,dv_x_mm_s,dv_y_g_s,dv_z_m_s\n"
             "0.01,1,3600,2,5,0.001,0.098\n");
  ImuReadOptions options;
  options.check_units = false;
  const ImuSample s = read_imu_csv(file, options).samples.at(0);
  EXPECT_DOUBLE_EQ(s.gyro.x(), M_PI / 180.0);
  EXPECT_DOUBLE_EQ(s.gyro.y(), M_PI / 180.0);  // 3600 arcsec = 1 deg
  EXPECT_DOUBLE_EQ(s.gyro.z(), 2e-3);
  EXPECT_DOUBLE_EQ(s.acc.x(), 5e-3);
  EXPECT_DOUBLE_EQ(s.acc.y(), 9.80665e-3);
  EXPECT_EQ(s.acc.z(), 0.098);
}

TEST_F(ImuCsv, TolerantOfCrLfBlanksAndPlusSignsButNotOfMissingNewlineByDefault) {
  const fs::path file = dir_ / "crlf.csv";
  write_text(file,
             "# imscal-imu: 1\r\n# quantity: rates\r\n# nominal_dt_s: 0.5\r\n"
             "t_s, gyro_x_rad_s ,gyro_y_rad_s,gyro_z_rad_s,acc_x_m_s2,acc_y_m_s2,acc_z_m_s2\r\n"
             "0.5, +1e-3 ,2,3,4,5,6\r\n"
             "1.0,1,2,3,4,5,6\r\n\r\n");
  ImuReadOptions options;
  options.check_units = false;
  const ImuSeries r = read_imu_csv(file, options);
  ASSERT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(r.samples[0].gyro.x(), 1e-3);
  EXPECT_EQ(r.samples[1].acc.z(), 6.0);
  // The same without the final line break: refused unless allowed.
  write_text(file,
             "# imscal-imu: 1\n# quantity: rates\n# nominal_dt_s: 0.5\n"
             "t_s,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s,acc_x_m_s2,acc_y_m_s2,acc_z_m_s2\n"
             "0.5,1,2,3,4,5,6\n1.0,1,2,3,4,5,6");
  EXPECT_THROW(read_imu_csv(file, options), InputError);
  options.allow_missing_final_newline = true;
  EXPECT_EQ(read_imu_csv(file, options).samples.size(), 2u);
}

TEST_F(ImuCsv, MissingFileIsAnInputError) {
  try {
    read_imu_csv(dir_ / "absent.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("absent.csv"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos);
  }
}

TEST_F(ImuCsv, FailedWritesLeaveNothingBehind) {
  ImuSeries s = make_series(100, 0.01, ImuQuantity::kRates, 5);
  s.samples[60].acc.y() = std::nan("");
  EXPECT_THROW(write_imu_csv(dir_ / "nan.csv", s, Overwrite::kAllow), std::invalid_argument);
  s = make_series(100, 0.01, ImuQuantity::kRates, 5);
  s.metadata = {{"bad key:", "x"}};
  EXPECT_THROW(write_imu_csv(dir_ / "key.csv", s, Overwrite::kAllow), std::invalid_argument);
  s.metadata = {{"quantity", "rates"}};  // reserved: would contradict the real header
  EXPECT_THROW(write_imu_csv(dir_ / "reserved.csv", s, Overwrite::kAllow), std::invalid_argument);
  s.metadata = {{"note", "two\nlines"}};
  EXPECT_THROW(write_imu_csv(dir_ / "value.csv", s, Overwrite::kAllow), std::invalid_argument);
  EXPECT_TRUE(fs::is_empty(dir_)) << "a failed write left a file (or a temporary) behind";
  // No directory: no file, no temporary.
  EXPECT_ANY_THROW(write_imu_csv(dir_ / "absent" / "x.csv",
                                 make_series(5, 0.01, ImuQuantity::kRates, 1), Overwrite::kAllow));
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(ImuCsv, RefusesToOverwriteAndKeepsTheOldFile) {
  const fs::path file = dir_ / "kept.csv";
  write_text(file, "precious\n");
  EXPECT_THROW(
      write_imu_csv(file, make_series(10, 0.01, ImuQuantity::kRates, 2), Overwrite::kRefuse),
      std::runtime_error);
  EXPECT_EQ(lines_of(file), std::vector<std::string>{"precious"});
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
  // Allowed: replaced as a whole.
  write_imu_csv(file, make_series(10, 0.01, ImuQuantity::kRates, 2), Overwrite::kAllow);
  ImuReadOptions options;
  options.check_units = false;  // 0.1 s: too short for a rest window
  EXPECT_EQ(read_imu_csv(file, options).samples.size(), 10u);
}

TEST_F(ImuCsv, FormatMatchesTheFile) {
  const ImuSeries s = make_series(30, 0.01, ImuQuantity::kIncrements, 9);
  const fs::path file = dir_ / "same.csv";
  write_imu_csv(file, s, Overwrite::kAllow);
  const std::string text = read_text(file);
  EXPECT_EQ(text, imscal::ims::format_imu_csv(s));
  EXPECT_TRUE(
      text.starts_with("# imscal-imu: 1\n# quantity: increments\n"
                       "# nominal_dt_s: 0.01\n"
                       "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_m_s,"
                       "dv_y_m_s,dv_z_m_s\n0.01,"));
}

}  // namespace
