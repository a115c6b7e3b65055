// Reader and defect checks of tool-IMU records, on the real MEMS files of the IMU_dataset
// (tests/data/real/abb-mems/SOURCE.md lists the defects the files are known to carry). The
// expected lines and time-step figures were read off the files independently with numpy
// (genfromtxt, NaN rows dropped, np.diff of t_s); the other expectations come from SOURCE.md.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "calib/tool_imu_record.hpp"
#include "core/input_error.hpp"
#include "core/units.hpp"
#include "tests/support/scratch_dir.hpp"

namespace imscal::calib {
namespace {

const std::string kDir = std::string(IMSCAL_TEST_DATA_DIR) + "/real/abb-mems/";

std::string path(const std::string& sequence, const std::string& sensor) {
  return kDir + "V_500_Sequencia" + sequence + "/" + sensor + ".csv";
}

std::vector<ToolImuFinding> of_kind(const std::vector<ToolImuFinding>& findings,
                                    ToolImuFindingKind kind) {
  std::vector<ToolImuFinding> out;
  for (const auto& f : findings) {
    if (f.kind == kind) out.push_back(f);
  }
  return out;
}

void print(const ToolImuAnalysis& analysis) {
  for (const auto& f : analysis.findings) {
    fmt::print("  [{}{}] {}: {}\n", to_string(f.kind), f.is_defect ? "" : " (ok)", f.where,
               f.message);
  }
}

TEST(ToolImuRecord, ReadsUnitsAndDropsNanRowsNamingTheLines) {
  // numpy: LSM9DS0 of sequence 1 has one NaN row (data index 367 = file line 369), 2157 rows.
  const auto record = read_tool_imu_record(path("1", "LSM9DS0"));
  ASSERT_TRUE(record.has_raw_imu);
  EXPECT_EQ(record.t_s.size(), 2156u);
  const auto nan = of_kind(record.findings, ToolImuFindingKind::kNanRows);
  ASSERT_EQ(nan.size(), 1u);
  EXPECT_EQ(nan[0].size, 1.0);
  EXPECT_NE(nan[0].where.find("369"), std::string::npos) << nan[0].where;
  EXPECT_EQ(std::count(record.lines.begin(), record.lines.end(), 369u), 0);
  // Units: line 3 of MPU9150 seq. 1 holds acc_z_g = 1.00060368 and robot_x_mm = 855.016
  // (exact conversion factors: 9.80665 m/s^2 per g, 1e-3 m per mm).
  const auto mpu = read_tool_imu_record(path("1", "MPU9150"));
  EXPECT_EQ(mpu.lines[1], 3u);
  EXPECT_DOUBLE_EQ(mpu.acc_m_s2[1].z(), 1.00060368 * 9.80665);
  EXPECT_DOUBLE_EQ(mpu.robot_position_m[1].x(), 0.855016);
  EXPECT_DOUBLE_EQ(mpu.gyro_rad_s[1].x(), -0.0145293446 * M_PI / 180.0);
  // NaN rows also in sequence 3 (numpy: line 370 in both raw files).
  for (const char* sensor : {"MPU9150", "LSM9DS0"}) {
    const auto r = read_tool_imu_record(path("3", sensor));
    const auto f = of_kind(r.findings, ToolImuFindingKind::kNanRows);
    ASSERT_EQ(f.size(), 1u) << sensor;
    EXPECT_NE(f[0].where.find("370"), std::string::npos) << f[0].where;
  }
}

TEST(ToolImuRecord, ReportsJitteredStepsAndGaps) {
  // numpy (NaN rows dropped): MPU9150 seq. 1 median step 9.934 ms, min 2.405 ms, max 35.71 ms;
  // LSM9DS0 seq. 3 has a 679.7 ms gap.
  const auto mpu = read_tool_imu_record(path("1", "MPU9150"));
  const auto steps = of_kind(mpu.findings, ToolImuFindingKind::kIrregularTimeSteps);
  ASSERT_EQ(steps.size(), 1u);
  EXPECT_TRUE(steps[0].is_defect);
  EXPECT_GT(steps[0].size, 0.3);  // ~42 % of the steps are > 50 % off the median (bursts)
  EXPECT_NE(steps[0].message.find("median 9.93 ms"), std::string::npos) << steps[0].message;
  EXPECT_NE(steps[0].message.find("min 2.41 ms"), std::string::npos) << steps[0].message;
  EXPECT_NE(steps[0].message.find("max 35.71 ms"), std::string::npos) << steps[0].message;
  const auto lsm = read_tool_imu_record(path("3", "LSM9DS0"));
  const auto lsm_steps = of_kind(lsm.findings, ToolImuFindingKind::kIrregularTimeSteps);
  ASSERT_EQ(lsm_steps.size(), 1u);
  EXPECT_NE(lsm_steps[0].message.find("max 679.71 ms"), std::string::npos) << lsm_steps[0].message;
  EXPECT_NE(lsm_steps[0].where.find("gaps before lines"), std::string::npos);
}

TEST(ToolImuRecord, ReportsRobotQuaternionsInterpolatedAcrossASignFlip) {
  // The 180 deg yaw of sequence 1 passes q = (0,0,0,1) -> (0,0,0,-1); component-wise
  // interpolation gives norms down to ~0 (numpy: min norm 1.9e-5 in MPU9150 seq. 1).
  const auto record = read_tool_imu_record(path("1", "MPU9150"));
  const auto f = of_kind(record.findings, ToolImuFindingKind::kRobotQuaternionNotUnit);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_GE(f[0].size, 5.0);
  std::size_t invalid = 0;
  for (std::size_t k = 0; k < record.t_s.size(); ++k) {
    if (!record.robot_pose_valid[k]) {
      ++invalid;
      EXPECT_GT(std::abs(record.robot_quaternion_norm[k] - 1.0), 0.01);
    } else {
      EXPECT_NEAR(record.q_B_T[k].norm(), 1.0, 1e-12);  // normalised
    }
  }
  EXPECT_EQ(static_cast<double>(invalid), f[0].size);
}

TEST(ToolImuRecord, DetectsEveryListedDefectOnTheRealFiles) {
  for (const char* sequence : {"1", "3"}) {
    for (const char* sensor : {"MPU9150", "LSM9DS0"}) {
      SCOPED_TRACE(fmt::format("sequence {} {}", sequence, sensor));
      const auto record = read_tool_imu_record(path(sequence, sensor));
      const auto analysis = check_tool_imu_record(record);
      print(analysis);
      // Time offset "of roughly 0.1 s" (SOURCE.md); cross-check: a brute-force correlation in
      // numpy gave 0.075-0.08 s on sequence 1. Accept 0.05-0.15 s.
      const auto offset = of_kind(analysis.findings, ToolImuFindingKind::kTimeOffset);
      ASSERT_EQ(offset.size(), 1u);
      EXPECT_TRUE(offset[0].is_defect);
      EXPECT_GT(analysis.time_offset_s, 0.05);
      EXPECT_LT(analysis.time_offset_s, 0.15);
      EXPECT_GT(analysis.time_offset_peak_correlation, 0.9);  // measured 0.957-0.981
      // The quaternion convention: only the conjugate reading has body rates that match the
      // gyros (measured: 14-17 % unexplained against 67-77 %).
      EXPECT_LT(analysis.rate_fit_residual, 0.5 * analysis.conjugate_rate_fit_residual);
      EXPECT_LT(analysis.rate_fit_residual, 0.25);
      const auto scale = of_kind(analysis.findings, ToolImuFindingKind::kGyroScaleMismatch);
      ASSERT_EQ(scale.size(), 1u);
      const auto axes = of_kind(analysis.findings, ToolImuFindingKind::kAxisMisalignment);
      ASSERT_EQ(axes.size(), 1u);
      const auto rails = of_kind(analysis.findings, ToolImuFindingKind::kGyroNearRail);
      if (std::string(sensor) == "LSM9DS0") {
        // "the LSM9DS0 gyro magnitude suggests a different unit or scale": measured 1/63.7 to
        // 1/63.9 of the robot's rate (neither deg/s nor rad/s = 1/57.3); accept 1/55..1/75.
        EXPECT_TRUE(scale[0].is_defect);
        EXPECT_GT(1.0 / analysis.gyro_scale_ratio, 55.0);
        EXPECT_LT(1.0 / analysis.gyro_scale_ratio, 75.0);
        // "the sensor axes are not aligned with the tool frame": x and y swapped (~94 deg).
        EXPECT_TRUE(axes[0].is_defect);
        EXPECT_NEAR(analysis.misalignment_rad * kDegPerRad, 90.0, 10.0);
      } else {
        // MPU9150: deg/s is right (measured ratio 0.987-1.012); its axes are within ~4 deg of
        // the tool's, reported but below the 5 deg threshold (measured 3.96 and 4.16 deg).
        EXPECT_FALSE(scale[0].is_defect);
        EXPECT_NEAR(analysis.gyro_scale_ratio, 1.0, 0.05);
        EXPECT_LT(analysis.misalignment_rad * kDegPerRad, 6.0);
        EXPECT_GT(analysis.misalignment_rad * kDegPerRad, 1.0);
        // "gyro saturation near 500 deg/s on MPU9150": a flat top on z at its largest reading,
        // 448.96 / 449.34 deg/s in the two files (numpy max |gyro_z_dps|).
        bool z_rail = false;
        for (const auto& f : rails) {
          if (f.where.find("gyro_z_dps") != std::string::npos) {
            z_rail = true;
            EXPECT_NEAR(f.size, 449.0, 1.0);
          }
        }
        EXPECT_TRUE(z_rail);
      }
    }
  }
}

TEST(ToolImuRecord, DetectsMotionTheSensorStreamLost) {
  // MPU9150, sequence 3: the robot turns 180 deg about z between 0.72 and 1.35 s while the
  // gyro integrates ~50 deg (numpy: cumulative trapezoid of gyro_z_dps).
  const auto record = read_tool_imu_record(path("3", "MPU9150"));
  const auto analysis = check_tool_imu_record(record);
  const auto lost = of_kind(analysis.findings, ToolImuFindingKind::kSensorMissedMotion);
  ASSERT_GE(lost.size(), 1u);
  EXPECT_NEAR(lost[0].size, 130.0, 20.0);  // 180 - 50 deg, segment edges +-0.15 s
  ASSERT_FALSE(analysis.missed_motion_spans_s.empty());
  EXPECT_LT(analysis.missed_motion_spans_s[0].first, 1.0);
  EXPECT_GT(analysis.missed_motion_spans_s[0].second, 1.4);
  // Sequence 1 has none (every segment's gyro angle agrees with the robot within 25 %).
  const auto clean = check_tool_imu_record(read_tool_imu_record(path("1", "MPU9150")));
  EXPECT_TRUE(of_kind(clean.findings, ToolImuFindingKind::kSensorMissedMotion).empty());
}

TEST(ToolImuRecord, ReadsAnAhrsOrientationFile) {
  const auto record = read_tool_imu_record(path("1", "XSENS"));
  EXPECT_TRUE(record.has_sensor_orientation);
  EXPECT_FALSE(record.has_raw_imu);
  ASSERT_EQ(record.q_N_X.size(), record.t_s.size());
  EXPECT_EQ(record.t_s.size(), 1123u);  // numpy: 1123 rows, none with NaN
  for (const auto& q : record.q_N_X) EXPECT_NEAR(q.norm(), 1.0, 1e-12);
  EXPECT_THROW(check_tool_imu_record(record), InputError);  // no raw gyro to check
}

// Bad input made from a real file: the first `rows` data lines of MPU9150 seq. 1, edited.
class ToolImuRecordBadInput : public test_support::ScratchDirTest {
 protected:
  std::vector<std::string> real_lines(std::size_t rows) {
    std::ifstream in(path("1", "MPU9150"));
    std::vector<std::string> lines;
    std::string line;
    while (lines.size() < rows + 1 && std::getline(in, line)) lines.push_back(line);
    return lines;
  }
  std::string write(const std::vector<std::string>& lines, const std::string& name) {
    const auto file = (dir_ / name).string();
    std::ofstream out(file);
    for (const auto& l : lines) out << l << '\n';
    return file;
  }
  void expect_error(const std::string& file, std::size_t line, const std::string& field) {
    try {
      read_tool_imu_record(file);
      ADD_FAILURE() << "no InputError for " << file;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), file);
      EXPECT_EQ(e.line(), line) << e.what();
      EXPECT_EQ(e.field(), field) << e.what();
    }
  }
};

TEST_F(ToolImuRecordBadInput, RefusesWithFileLineAndField) {
  auto lines = real_lines(50);
  {  // empty file
    expect_error(write({}, "empty.csv"), 1, "");
  }
  {  // a column renamed (unit changed in the name): unknown column
    auto bad = lines;
    bad[0].replace(bad[0].find("gyro_y_dps"), 10, "gyro_y_rad");
    expect_error(write(bad, "renamed.csv"), 1, "gyro_y_rad");
  }
  {  // a column missing (header and rows lose acc_z_g consistently: still refused)
    auto bad = lines;
    bad[0].replace(bad[0].find(",acc_z_g"), 8, "");
    expect_error(write(bad, "missing.csv"), 1, "acc_z_g");
  }
  {  // truncated last row (cut inside robot_y_mm)
    auto bad = lines;
    const auto cut = bad[30].find(',', bad[30].find("855"));
    bad[30] = bad[30].substr(0, cut);
    bad.resize(31);
    expect_error(write(bad, "truncated.csv"), 31, "robot_y_mm");
  }
  {  // text that is not a number
    auto bad = lines;
    bad[10].replace(bad[10].find(','), 1, ",abc");
    expect_error(write(bad, "text.csv"), 11, "gyro_x_dps");
  }
  {  // time going back: rows 20 and 21 swapped
    auto bad = lines;
    std::swap(bad[20], bad[21]);
    expect_error(write(bad, "backwards.csv"), 22, "t_s");
  }
  {  // a NaN row is NOT an error: dropped and reported
    auto edited = lines;
    edited[5] = "nan,nan,nan,nan,nan,nan,nan,855,0,1170,1,0,0,0";
    const auto record = read_tool_imu_record(write(edited, "nan.csv"));
    EXPECT_EQ(record.t_s.size(), 49u);
    ASSERT_EQ(of_kind(record.findings, ToolImuFindingKind::kNanRows).size(), 1u);
  }
}

}  // namespace
}  // namespace imscal::calib
