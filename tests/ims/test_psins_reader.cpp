// PSINS count-format reader: units and time stamps against hand arithmetic on small files, the
// real RLG record (tests/data/real/rlg-static), and bad inputs (tests/data/bad_inputs/psins).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/input_error.hpp"
#include "ims/psins_reader.hpp"

namespace imscal::ims {
namespace {

namespace fs = std::filesystem;
const fs::path kData = IMSCAL_TEST_DATA_DIR;

fs::path write_temp(const std::string& name, const std::string& content) {
  const fs::path path = fs::temp_directory_path() / ("imscal_test_psins_" + name);
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

TEST(PsinsReader, ConvertsCountsWithPerAxisScalesAndTheFilesG) {
  const fs::path path = write_temp("small.imu",
                                   "% comment line\n"
                                   "\n"
                                   "1.5 -2.0 30.0 0.1 0.2 0.3\n"
                                   "48.0 9.0 250.0 100.0 5.0 9.81\n"
                                   "0.1 0.2 0.4 100.0 200.0 50.0\r\n"  // CRLF tolerated
                                   "10 -20 3 1 2 -196\n"
                                   "  0 0 0 0 0 0  \n");
  PsinsHeader header;
  const ImuSeries s = read_psins(path, &header);
  ASSERT_EQ(s.samples.size(), 2u);
  EXPECT_EQ(s.quantity, ImuQuantity::kIncrements);
  EXPECT_EQ(s.first_data_line, 6u);  // line numbers: comment, blank, 3 headers, then data
  EXPECT_EQ(header.header_lines[0], 3u);
  EXPECT_DOUBLE_EQ(s.nominal_dt_s, 0.005);  // 5 ms
  // Stamps at the end of each interval: t0 + k dt, k = 1, 2.
  EXPECT_DOUBLE_EQ(s.samples[0].t_s, 100.005);
  EXPECT_DOUBLE_EQ(s.samples[1].t_s, 100.010);
  // Hand arithmetic: arcsec -> rad is pi / 648000; ug*s -> m/s is 1e-6 * g.
  const double arcsec = M_PI / 648000.0;
  // 1e-15 relative: a few roundings of double products.
  EXPECT_NEAR(s.samples[0].gyro.x(), 10 * 0.1 * arcsec, 1e-15 * arcsec);
  EXPECT_NEAR(s.samples[0].gyro.y(), -20 * 0.2 * arcsec, 1e-15 * arcsec);
  EXPECT_NEAR(s.samples[0].gyro.z(), 3 * 0.4 * arcsec, 1e-15 * arcsec);
  EXPECT_NEAR(s.samples[0].acc.x(), 1 * 100.0e-6 * 9.81, 1e-15);
  EXPECT_NEAR(s.samples[0].acc.y(), 2 * 200.0e-6 * 9.81, 1e-15);
  EXPECT_NEAR(s.samples[0].acc.z(), -196 * 50.0e-6 * 9.81, 1e-15);
  EXPECT_TRUE(s.samples[1].gyro.isZero(0.0));
  ASSERT_TRUE(s.site.has_value());
  EXPECT_DOUBLE_EQ(s.site->latitude_deg, 48.0);
  EXPECT_DOUBLE_EQ(s.site->longitude_deg, 9.0);
  EXPECT_DOUBLE_EQ(s.site->height_m, 250.0);
  EXPECT_DOUBLE_EQ(header.initial_pitch_deg, 1.5);
  EXPECT_DOUBLE_EQ(header.initial_roll_deg, -2.0);
  EXPECT_DOUBLE_EQ(header.initial_yaw_deg, 30.0);
  EXPECT_DOUBLE_EQ(header.initial_velocity_enu_m_s.z(), 0.3);
  EXPECT_DOUBLE_EQ(header.gravity_m_s2, 9.81);
  EXPECT_DOUBLE_EQ(header.acc_scale_ug_s_per_count.y(), 200.0);
  EXPECT_EQ(s.source, path.string());
  fs::remove(path);
}

TEST(PsinsReader, ReadsTheRealRingLaserGyroRecord) {
  PsinsHeader header;
  const ImuSeries s = read_psins(kData / "real/rlg-static/lasergyro.imu", &header);
  // 184,732 lines: 10 comment lines, 1 blank, 3 header lines, 184,718 samples.
  ASSERT_EQ(s.samples.size(), 184718u);
  EXPECT_EQ(s.first_data_line, 15u);
  EXPECT_DOUBLE_EQ(header.initial_yaw_deg, -90.6);
  EXPECT_DOUBLE_EQ(header.site.latitude_deg, 34.246048);
  EXPECT_DOUBLE_EQ(header.site.longitude_deg, 108.909664);
  EXPECT_DOUBLE_EQ(header.site.height_m, 380.0);
  EXPECT_DOUBLE_EQ(header.interval_s, 0.01);
  EXPECT_DOUBLE_EQ(header.gravity_m_s2, 9.780327);
  EXPECT_NEAR(s.samples.back().t_s, 1847.18, 1e-9);  // 184718 * 10 ms, rounding of the sum
  // First line "0 0 2 0 0 80": 2 * 0.1 arcsec and 80 * 125 ug*s.
  EXPECT_NEAR(s.samples[0].gyro.z(), 0.2 * M_PI / 648000.0, 1e-20);
  EXPECT_NEAR(s.samples[0].acc.z(), 80 * 125e-6 * 9.780327, 1e-15);
  // At rest the mean specific force is g: 80 counts per 10 ms at 125 ug*s is 1.000 g.
  double sum_z = 0.0;
  for (const auto& sample : s.samples) sum_z += sample.acc.z();
  const double mean_f_z = sum_z / (s.samples.size() * header.interval_s);
  EXPECT_NEAR(mean_f_z, 9.79, 0.02);  // g at the site 9.7955; tilt 1 deg changes < 2e-3
}

struct BadCase {
  const char* file;
  std::size_t line;   // expected line of the error (0: whole file)
  const char* field;  // expected field name
};

class PsinsBadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(PsinsBadInput, RaisesInputErrorNamingLineAndField) {
  const BadCase& c = GetParam();
  const fs::path path = kData / "bad_inputs/psins" / c.file;
  try {
    read_psins(path);
    FAIL() << c.file << " was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_EQ(e.line(), c.line) << e.what();
    EXPECT_EQ(e.field(), c.field) << e.what();
    EXPECT_FALSE(e.problem().empty());
  }
}

INSTANTIATE_TEST_SUITE_P(
    Files, PsinsBadInput,
    ::testing::Values(BadCase{"empty.imu", 0, ""}, BadCase{"header_only.imu", 4, ""},
                      BadCase{"missing_header_line.imu", 3, "gyro_scale_x_arcsec_per_count"},
                      BadCase{"short_header_line.imu", 3, "g_m_s2"},
                      BadCase{"wrong_column_count.imu", 6, "acc_z_count"},
                      BadCase{"non_numeric_count.imu", 6, "gyro_z_count"},
                      BadCase{"non_integer_count.imu", 6, "acc_y_count"},
                      BadCase{"nan_count.imu", 6, "gyro_y_count"},
                      BadCase{"nan_gravity.imu", 3, "g_m_s2"},
                      BadCase{"truncated_last_line.imu", 7, "acc_y_count"},
                      BadCase{"zero_interval.imu", 3, "interval_ms"},
                      BadCase{"gravity_in_g.imu", 3, "g_m_s2"},
                      BadCase{"negative_scale.imu", 4, "gyro_scale_z_arcsec_per_count"},
                      BadCase{"extra_column.imu", 5, ""}),
    [](const ::testing::TestParamInfo<BadCase>& info) {
      std::string name = info.param.file;
      return name.substr(0, name.find('.'));
    });

TEST(PsinsReader, MissingFileIsAnInputError) {
  EXPECT_THROW(read_psins(kData / "bad_inputs/psins/does_not_exist.imu"), InputError);
}

}  // namespace
}  // namespace imscal::ims
