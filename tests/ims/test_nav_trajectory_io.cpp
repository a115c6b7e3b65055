// Trajectory files: CSV written and read back bit for bit (with and without sigmas), TUM read
// back by an independent parser, and every kind of bad CSV refused with file, line and field.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "core/input_error.hpp"
#include "ims/nav_trajectory_io.hpp"

namespace ims = imscal::ims;
namespace fs = std::filesystem;

namespace {

class NavTrajectoryIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("imscal_nav_io_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::vector<ims::NavState> random_states(int n) {
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> uniform(-3.0, 3.0);
    std::vector<ims::NavState> states;
    for (int i = 0; i < n; ++i) {
      ims::NavState s;
      s.t_s = 100.0 + i * 1e-3 + uniform(rng) * 1e-5;
      s.q_W_S = Eigen::Quaterniond(uniform(rng), uniform(rng), uniform(rng), uniform(rng));
      s.q_W_S.normalize();
      s.v_W = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)) * 1e-3;
      s.p_W = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)) * 1e5;
      states.push_back(s);
    }
    return states;
  }

  void write_text(const fs::path& file, const std::string& text) {
    std::ofstream(file, std::ios::binary) << text;
  }

  // Expects read_trajectory_csv to refuse `text` with an InputError at `line` naming `field`.
  void expect_refused(const std::string& text, std::size_t line, const std::string& field) {
    const fs::path file = dir_ / "bad.csv";
    write_text(file, text);
    try {
      ims::read_trajectory_csv(file);
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const imscal::InputError& e) {
      EXPECT_EQ(e.file(), file.string());
      EXPECT_EQ(e.line(), line) << e.what();
      EXPECT_EQ(e.field(), field) << e.what();
    }
  }

  fs::path dir_;
};

const std::string kHeader = "t_s,x_m,y_m,z_m,qw,qx,qy,qz,vx_m_s,vy_m_s,vz_m_s\n";

}  // namespace

TEST_F(NavTrajectoryIo, CsvRoundTripIsExact) {
  const auto states = random_states(500);
  const fs::path file = dir_ / "trajectory.csv";
  ims::write_trajectory_csv(file, states);
  const ims::NavTrajectory read = ims::read_trajectory_csv(file);
  ASSERT_EQ(read.states.size(), states.size());
  EXPECT_TRUE(read.sigmas.empty());
  for (std::size_t i = 0; i < states.size(); ++i) {
    // Shortest round-trip formatting: times, positions and velocities come back bit for bit.
    EXPECT_EQ(read.states[i].t_s, states[i].t_s);
    EXPECT_EQ(read.states[i].p_W, states[i].p_W);
    EXPECT_EQ(read.states[i].v_W, states[i].v_W);
    // The quaternion is renormalised on reading, which may move its last bit.
    EXPECT_LT((read.states[i].q_W_S.coeffs() - states[i].q_W_S.coeffs()).norm(), 1e-15);
  }
  std::ifstream in(file);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first + "\n", kHeader);
}

TEST_F(NavTrajectoryIo, CsvWithSigmasRoundTrip) {
  const auto states = random_states(50);
  std::vector<ims::NavSigma> sigmas;
  for (int i = 0; i < 50; ++i) sigmas.push_back(ims::NavSigma::Constant(1e-4 * (i + 1)));
  const fs::path file = dir_ / "trajectory.csv";
  ims::write_trajectory_csv(file, states, &sigmas);
  const ims::NavTrajectory read = ims::read_trajectory_csv(file);
  ASSERT_EQ(read.sigmas.size(), sigmas.size());
  for (std::size_t i = 0; i < sigmas.size(); ++i) EXPECT_EQ(read.sigmas[i], sigmas[i]);

  std::vector<ims::NavSigma> too_few(3);
  EXPECT_THROW(ims::write_trajectory_csv(dir_ / "x.csv", states, &too_few), std::invalid_argument);
}

TEST_F(NavTrajectoryIo, TumHoldsTimePositionAndQuaternionXyzw) {
  const auto states = random_states(20);
  const fs::path file = dir_ / "trajectory.tum";
  ims::write_trajectory_tum(file, states);
  std::ifstream in(file);
  std::string line;
  std::size_t i = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t, x, y, z, qx, qy, qz, qw;
    ASSERT_TRUE(fields >> t >> x >> y >> z >> qx >> qy >> qz >> qw) << line;
    std::string rest;
    EXPECT_FALSE(fields >> rest) << "extra field in " << line;
    ASSERT_LT(i, states.size());
    EXPECT_EQ(t, states[i].t_s);
    EXPECT_EQ(Eigen::Vector3d(x, y, z), states[i].p_W);
    EXPECT_EQ(Eigen::Vector4d(qx, qy, qz, qw), states[i].q_W_S.coeffs());  // Eigen: x, y, z, w
    ++i;
  }
  EXPECT_EQ(i, states.size());
}

TEST_F(NavTrajectoryIo, RefusesToOverwriteWhenAskedTo) {
  const auto states = random_states(2);
  const fs::path file = dir_ / "trajectory.csv";
  ims::write_trajectory_csv(file, states);
  EXPECT_THROW(ims::write_trajectory_csv(file, states, nullptr, imscal::Overwrite::kRefuse),
               std::runtime_error);
  EXPECT_THROW(ims::write_trajectory_tum(file, states, imscal::Overwrite::kRefuse),
               std::runtime_error);
  EXPECT_EQ(ims::read_trajectory_csv(file).states.size(), 2u);  // untouched
}

TEST_F(NavTrajectoryIo, RefusesBadCsv) {
  const std::string good = "1,0,0,0,1,0,0,0,0,0,0\n";
  expect_refused("t,x_m,y_m,z_m,qw,qx,qy,qz,vx_m_s,vy_m_s,vz_m_s\n" + good, 1, "");
  expect_refused("# comment\n" + kHeader + good + "2,0,0,0,1,0,0,0,0,0\n", 4, "");
  expect_refused(kHeader + good + "2,0,abc,0,1,0,0,0,0,0,0\n", 3, "y_m");
  expect_refused(kHeader + good + "2,0,0,0,1,0,0,0,0,0,nan\n", 3, "vz_m_s");
  expect_refused(kHeader + good + "0.5,0,0,0,1,0,0,0,0,0,0\n", 3, "t_s");
  expect_refused(kHeader + good + "2,0,0,0,0.9,0,0,0,0,0,0\n", 3, "qw");
  expect_refused("", 0, "");
  const std::string sigma_header =
      "t_s,x_m,y_m,z_m,qw,qx,qy,qz,vx_m_s,vy_m_s,vz_m_s,sigma_att_e_rad,sigma_att_n_rad,"
      "sigma_att_u_rad,sigma_vx_m_s,sigma_vy_m_s,sigma_vz_m_s,sigma_x_m,sigma_y_m,sigma_z_m\n";
  expect_refused(sigma_header + "1,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0,-1,0\n", 2, "sigma_y_m");
}
