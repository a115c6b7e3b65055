// Two inertial units as a tool-IMU record: PSINS's attitude matrix against its a2mat formula
// written out, the slave's rate placed mid-interval with the master's attitude slerped there, and
// the readers' refusals (file, line, column).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "calib/master_slave_record.hpp"
#include "core/input_error.hpp"
#include "tests/support/scratch_dir.hpp"

namespace imscal::calib {
namespace {

// PSINS base/base0/a2mat.m, element by element (att = [pitch; roll; yaw]).
Eigen::Matrix3d a2mat(double p, double r, double y) {
  const double sp = std::sin(p), cp = std::cos(p), sr = std::sin(r), cr = std::cos(r),
               sy = std::sin(y), cy = std::cos(y);
  Eigen::Matrix3d C;
  C << cy * cr - sy * sp * sr, -sy * cp, cy * sr + sy * sp * cr,  //
      sy * cr + cy * sp * sr, cy * cp, sy * sr - cy * sp * cr,    //
      -cp * sr, sp, cp * cr;
  return C;
}

TEST(MasterSlaveRecord, PsinsAttitudeIsA2mat) {
  for (const Eigen::Vector3d& a :
       {Eigen::Vector3d(0.1, -0.5, 2.0), Eigen::Vector3d(-1.2, 0.3, -0.7)}) {
    // Rounding only: 1e-15 per element.
    EXPECT_LT((psins_attitude(a.x(), a.y(), a.z()).toRotationMatrix() - a2mat(a.x(), a.y(), a.z()))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-15);
  }
}

// A master turning at 0.2 rad/s about its z axis, sampled at 10 Hz; a slave with increments of
// the same turn at 100 Hz: every row's rate is 0.2 rad/s at the middle of its interval, and the
// master's attitude there is the slerp, exactly Rz(0.2 t) (a constant-rate turn is a geodesic).
TEST(MasterSlaveRecord, RatesMidIntervalAndTheMasterSlerped) {
  IncrementImu slave;
  for (int k = 0; k <= 100; ++k) {
    slave.t_end_s.push_back(0.01 * k);
    slave.lines.push_back(k + 2);
    slave.dtheta_rad.push_back(Eigen::Vector3d(0, 0, 0.2 * 0.01));
    slave.dv_m_s.push_back(Eigen::Vector3d(0, 0, 9.8 * 0.01));
  }
  InsAttitude master;
  for (int j = 0; j <= 10; ++j) {
    master.t_s.push_back(0.1 * j);
    master.q_N_B.push_back(psins_attitude(0, 0, 0.2 * 0.1 * j));
  }
  const ToolImuRecord r = master_slave_record(slave, master);
  ASSERT_EQ(r.t_s.size(), 100u);
  for (std::size_t k = 0; k < r.t_s.size(); ++k) {
    EXPECT_NEAR(r.t_s[k], 0.01 * k + 0.005, 1e-12);
    EXPECT_NEAR(r.gyro_rad_s[k].z(), 0.2, 1e-12);
    EXPECT_TRUE(r.robot_pose_valid[k]);
    EXPECT_LT(r.q_B_T[k].angularDistance(psins_attitude(0, 0, 0.2 * r.t_s[k])), 1e-12);
  }
}

class MasterSlaveFiles : public test_support::ScratchDirTest {
 protected:
  std::filesystem::path write(const std::string& text) {
    const std::filesystem::path file = dir_ / "in.csv";
    std::ofstream(file) << text;
    return file;
  }
};

TEST_F(MasterSlaveFiles, RefusesTimeBackwardsDegreesAndAMissingColumn) {
  const std::string imu_header =
      "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n";
  try {
    read_increment_imu_csv(write(imu_header + "0.01,0,0,0,0,0,0.1\n0.01,0,0,0,0,0,0.1\n"));
    FAIL() << "time does not increase";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3u);
    EXPECT_EQ(e.field(), "t_s");
  }
  try {
    read_increment_imu_csv(write(imu_header + "0.01,0,0,0,0,0,0.1\n0.02,2,0,0,0,0,0.1\n"));
    FAIL() << "an increment of 2 rad";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3u);
  }
  try {
    read_psins_attitude_csv(write("t_s,pitch_rad,roll_rad,yaw_rad\n0.1,0,30,0\n0.2,0,0,0\n"));
    FAIL() << "degrees";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 2u);
    EXPECT_EQ(e.field(), "roll_rad");
  }
  try {
    read_psins_attitude_csv(write("t_s,pitch_rad,roll_rad\n0.1,0,0\n0.2,0,0\n"));
    FAIL() << "no yaw";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "yaw_rad");
  }
}

}  // namespace
}  // namespace imscal::calib
