// The frame calibration's parameter layout and the result's look-up by name: rows follow the
// order of declaration, a subset block reports only its estimated entries, quaternions are
// reported as rotation vectors, and a name that is not estimated is refused.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "calib/frame_calibration.hpp"
#include "calib/frame_parameter_layout.hpp"

namespace imscal::calib {
namespace {

TEST(FrameParameterLayout, RowsFollowTheOrderOfDeclaration) {
  // A rotation of 0.3 rad about (1, 2, 2)/3: its rotation vector is the truth (closed form).
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
  Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, axis));
  double quaternion[4] = {q.x(), q.y(), q.z(), q.w()};
  double bias[3] = {1e-5, -2e-5, 3e-5};
  double dt[1] = {0.0123};
  double windup[6] = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  FrameParameterLayout layout;
  layout.add_quaternion("R_W_R", quaternion, {"east", "north", "up"});
  layout.add("gyro_bias", bias, {"x", "y", "z"});
  layout.add("time_offset", dt, {"dt"});
  layout.add("windup_scale_deviation", windup, {"A2", "A5"}, {1, 4});

  EXPECT_EQ(layout.offset("R_W_R"), 0);
  EXPECT_EQ(layout.offset("gyro_bias"), 3);
  EXPECT_EQ(layout.offset("time_offset"), 6);
  EXPECT_EQ(layout.index("windup_scale_deviation", "A5"), 8);
  EXPECT_FALSE(layout.find("windup_scale_deviation", "A1").has_value());
  EXPECT_FALSE(layout.contains("link_share"));
  EXPECT_THROW(layout.offset("link_share"), std::out_of_range);
  ASSERT_EQ(layout.covariance_blocks().size(), 4u);
  EXPECT_EQ(layout.covariance_blocks()[0].tangent_to_si, 2.0);  // quaternion tangent
  EXPECT_EQ(layout.covariance_blocks()[3].tangent_size, 2);

  const Eigen::VectorXd v = layout.values();
  ASSERT_EQ(v.size(), 9);
  // Rotation vector against the angle-axis it was made from: round-off of a few ulp.
  EXPECT_LT((v.head<3>() - 0.3 * axis).norm(), 1e-15);
  EXPECT_EQ(v[4], -2e-5);
  EXPECT_EQ(v[6], 0.0123);
  EXPECT_EQ(v[7], 0.2);
  EXPECT_EQ(v[8], 0.5);
}

TEST(FrameCalibrationResult, SigmaAndValueByName) {
  FrameCalibrationResult r;
  r.parameter_names = {"gyro_bias.x", "gyro_bias.y", "time_offset.dt", "link_share.s"};
  r.parameter_values = Eigen::Vector4d(1e-5, 2e-5, 0.0123, 0.4);
  r.covariance = Eigen::Vector4d(4e-12, 9e-12, 1e-10, 0.0025).asDiagonal();
  // sqrt of a rounded square: within a few ulp (EXPECT_DOUBLE_EQ).
  EXPECT_DOUBLE_EQ(r.sigma("gyro_bias.y"), 3e-6);
  EXPECT_DOUBLE_EQ(r.sigma("time_offset"), 1e-5);  // a block of one component by its name
  EXPECT_DOUBLE_EQ(r.sigma("link_share"), 0.05);
  EXPECT_EQ(r.value("time_offset"), 0.0123);
  EXPECT_EQ(r.value("gyro_bias.x"), 1e-5);
  EXPECT_THROW(r.sigma("gyro_bias"), std::out_of_range);  // two components: ambiguous
  EXPECT_THROW(r.sigma("acc_bias.x"), std::out_of_range);
  r.covariance.resize(0, 0);  // the covariance failed: names without sigmas
  EXPECT_THROW(r.sigma("gyro_bias.x"), std::out_of_range);
}

}  // namespace
}  // namespace imscal::calib
