// calib::frames_json's document read back by calib::read_frames_json gives the frames, their
// covariance and the link share written; calib::read_frames_json against the values written into a
// frames.json (datasets/FORMAT.md
// §16.2): the rotations from their quaternions, T_S_H's translation from mm, the covariance block
// of the frames and the optional link share; and its refusals naming file and field. The command
// line's refusals of --frames are tested in test_calibrate_two_sessions.cpp.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "calib/frames_json.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "tests/support/refused_file.hpp"
#include "tests/support/scratch_dir.hpp"

namespace imscal::calib {
namespace {

using nlohmann::json;
using FramesJsonTest = test_support::ScratchDirTest;

// T_R_W: 30 deg about the vertical (the base's yaw in the shipped scenarios).
const Eigen::Quaterniond kQ_R_W(Eigen::AngleAxisd(M_PI / 6.0, Eigen::Vector3d::UnitZ()));

json frames_file() {
  json covariance = json::array();
  for (int r = 0; r < 10; ++r) {
    json row = json::array();
    for (int c = 0; c < 10; ++c) row.push_back(r == c ? 1e-8 * (r + 1) : (r + c == 1 ? 2e-9 : 0.0));
    covariance.push_back(row);
  }
  return {{"imscal-frames", 1},
          {"robot", "kr16"},
          {"T_R_W",
           {{"xyz_mm", {2000.0, 1000.0, 0.0}},
            {"quaternion_wxyz", {kQ_R_W.w(), kQ_R_W.x(), kQ_R_W.y(), kQ_R_W.z()}}}},
          {"T_S_H", {{"xyz_mm", {1.5, -0.8, -120.4}}, {"quaternion_wxyz", {1, 0, 0, 0}}}},
          {"parameter_names",
           {"R_W_R.east", "R_W_R.north", "R_W_R.up", "R_S_H.x", "R_S_H.y", "R_S_H.z", "p_S_H.x",
            "p_S_H.y", "p_S_H.z", "time_offset"}},
          {"covariance_si", covariance},
          {"estimates",
           {{{"name", "link_share (of the drives' viscous friction)"},
             {"value", {0.12}},
             {"sigma", {0.03}}}}}};
}

TEST_F(FramesJsonTest, ReadsTheFramesTheirCovarianceAndTheLinkShare) {
  const auto file = dir_ / "frames.json";
  std::ofstream(file) << frames_file().dump(1);
  const SessionFrames s = read_frames_json(file, "kr16");
  // The quaternions are written to 17 digits: the rotations agree to rounding (1e-15).
  EXPECT_LT((s.frames.R_W_R - kQ_R_W.toRotationMatrix().transpose()).norm(), 1e-15);
  EXPECT_LT((s.frames.T_S_H.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-15);
  EXPECT_LT((s.frames.T_S_H.translation() - Eigen::Vector3d(1.5e-3, -0.8e-3, -0.1204)).norm(),
            1e-15);
  // The frames' 9 x 9 block, without the tenth parameter.
  EXPECT_DOUBLE_EQ(s.frames.covariance(0, 0), 1e-8);
  EXPECT_DOUBLE_EQ(s.frames.covariance(8, 8), 9e-8);
  EXPECT_DOUBLE_EQ(s.frames.covariance(0, 1), 2e-9);
  EXPECT_DOUBLE_EQ(s.frames.covariance(2, 3), 0.0);
  ASSERT_TRUE(s.link_share.has_value());
  EXPECT_DOUBLE_EQ(*s.link_share, 0.12);
  EXPECT_DOUBLE_EQ(*s.link_share_sigma, 0.03);
  EXPECT_EQ(s.robot, "kr16");
  EXPECT_EQ(s.sha256.size(), 64u);
}

TEST_F(FramesJsonTest, RefusalsNameTheFileAndTheField) {
  const auto file = dir_ / "frames.json";
  struct Case {
    std::string text;
    std::string field;
  };
  json off_unit = frames_file();
  off_unit["T_S_H"]["quaternion_wxyz"] = {1.0, 0.01, 0.0, 0.0};
  json short_covariance = frames_file();
  while (short_covariance["covariance_si"].size() > 8) short_covariance["covariance_si"].erase(8);
  json negative = frames_file();
  negative["covariance_si"][3][3] = -1e-9;
  std::string repeated = frames_file().dump(1);
  repeated.insert(repeated.find("\"robot\""), "\"robot\": \"kr16\",\n ");
  const std::vector<Case> cases = {
      {off_unit.dump(), "T_S_H.quaternion_wxyz"}, {short_covariance.dump(), "covariance_si"},
      {negative.dump(), "covariance_si[3][3]"},   {repeated, "robot"},
      {"{\"imscal-frames\": 1, \"robot\": ", ""},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text.substr(0, 60));
    test_support::expect_refused_naming_field(
        [](const std::filesystem::path& f) { read_frames_json(f, "kr16"); }, file, c.text, c.field);
  }
}

TEST_F(FramesJsonTest, TheWritersDocumentIsReadBackWithTheSameValues) {
  FrameCalibrationResult result;
  result.T_R_W = Eigen::Translation3d(2.0, 1.0, 0.3) * kQ_R_W;
  result.T_S_H = Eigen::Translation3d(0.0015, -0.0008, -0.1204) *
                 Eigen::AngleAxisd(0.02, Eigen::Vector3d(1.0, -2.0, 0.5).normalized());
  result.parameter_names = {"R_W_R.east", "R_W_R.north", "R_W_R.up", "R_S_H.x", "R_S_H.y",
                            "R_S_H.z",    "p_S_H.x",     "p_S_H.y",  "p_S_H.z", "time_offset"};
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(10, 10) * 1e-4;
  result.covariance = a * a.transpose();  // symmetric, positive definite
  result.correlation = Eigen::MatrixXd::Identity(10, 10);
  result.estimates = {{"link_share (of the drives' viscous friction)",
                       "",
                       {"share"},
                       Eigen::VectorXd::Constant(1, 0.31),
                       Eigen::VectorXd::Constant(1, 0.07)}};
  FramesJsonContext context;
  context.created_by = "imscal 9.8.7";
  context.robot = "kr16";
  const auto file = dir_ / "frames.json";
  std::ofstream(file) << json_text(frames_json(result, context), 1, file.string());
  const SessionFrames s = read_frames_json(file, "kr16");
  // Quaternions and mm are written to 17 significant digits: equal to ~1e-15 after the unit
  // conversions on the way out and back.
  EXPECT_LT((s.frames.R_W_R - result.T_R_W.linear().transpose()).norm(), 1e-15);
  EXPECT_LT((s.frames.T_S_H.matrix() - result.T_S_H.matrix()).norm(), 1e-15);
  EXPECT_EQ(s.frames.covariance, result.covariance.topLeftCorner(9, 9));  // SI as written
  ASSERT_TRUE(s.link_share.has_value());
  EXPECT_EQ(*s.link_share, 0.31);
  EXPECT_EQ(*s.link_share_sigma, 0.07);
  EXPECT_EQ(s.robot, "kr16");
  EXPECT_THROW(read_frames_json(file, "ur10"), InputError);
}

}  // namespace
}  // namespace imscal::calib
