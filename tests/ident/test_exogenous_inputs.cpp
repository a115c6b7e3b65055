// The one definition of the ARX models' further inputs (ident/exogenous_inputs.hpp) against
// their closed forms, and the descriptors against the names parameters.json uses.
#include "ident/exogenous_inputs.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

namespace imscal::ident {
namespace {

TEST(ExogenousInputs, ValuesAreTheClosedForms) {
  ExogenousParameters p;
  p.direction_speed_scale_rad_s = 0.02;
  p.torque_sign_scale_nm = 3.0;
  p.transmission_error_rad_per_rad = 2.0 * 121.0;  // harmonic 2 x gear ratio 121
  p.transmission_error_compliance_rad_per_nm = 1.0 / 2.0e5;
  const ExogenousSample s{0.7, -0.015, 42.0};
  const std::vector<TableInput> inputs = {
      TableInput::kTransmissionErrorCos, TableInput::kModelTorque, TableInput::kDirection,
      TableInput::kTorqueSign, TableInput::kTransmissionErrorSin};
  std::array<double, 5> v{};
  exogenous_values(inputs, p, s, v.data());
  // Written from the definitions, not from the code: phase f (x + τ / k).
  const double phase = 242.0 * (0.7 + 42.0 / 2.0e5);
  // 1e-15 relative: the same operations may be ordered differently by the compiler (a few ulp).
  EXPECT_NEAR(v[0], std::cos(phase), 1e-15);
  EXPECT_EQ(v[1], 42.0);
  EXPECT_NEAR(v[2], std::tanh(-0.015 / 0.02), 1e-15);
  EXPECT_NEAR(v[3], std::tanh(42.0 / 3.0), 1e-15);
  EXPECT_NEAR(v[4], std::sin(phase), 1e-15);
}

TEST(ExogenousInputs, WithoutComplianceThePhaseIgnoresTheTorque) {
  ExogenousParameters p;
  p.transmission_error_rad_per_rad = 50.0;
  const double with_torque = exogenous_value(TableInput::kTransmissionErrorSin, p, {0.3, 0.0, 9.0});
  EXPECT_EQ(with_torque, std::sin(50.0 * 0.3));
}

TEST(ExogenousInputs, DescriptorsNameEveryKindInEnumOrder) {
  const char* names[] = {"model_torque",
                         "direction",
                         "torque_sign",
                         "transmission_error_sin",
                         "transmission_error_cos",
                         "transmission_error_2_sin",
                         "transmission_error_2_cos",
                         "transmission_error_mode_sin",
                         "transmission_error_mode_cos",
                         "transmission_error_2_mode_sin",
                         "transmission_error_2_mode_cos"};
  ASSERT_EQ(kExogenousInputKindCount, 11);
  for (int k = 0; k < kExogenousInputKindCount; ++k) {
    EXPECT_EQ(int(kExogenousInputKinds[k].input), k);
    EXPECT_STREQ(to_string(TableInput(k)), names[k]);
  }
}

TEST(ExogenousInputs, RefusesMissingTorqueAndBadConstants) {
  const std::vector<TableInput> sign_only = {TableInput::kTorqueSign};
  EXPECT_EQ(exogenous_inputs_problem(sign_only),
            "the torque-sign input needs the model torque input");
  const std::vector<TableInput> pair = {TableInput::kTransmissionErrorSin,
                                        TableInput::kTransmissionErrorCos};
  EXPECT_EQ(exogenous_inputs_problem(pair), "");
  ExogenousParameters p;
  EXPECT_EQ(exogenous_parameters_problem(pair, p),
            "the transmission-error inputs need a phase rate > 0");
  p.transmission_error_rad_per_rad = 10.0;
  EXPECT_EQ(exogenous_parameters_problem(pair, p), "");
  p.transmission_error_compliance_rad_per_nm = 1e-5;
  EXPECT_EQ(exogenous_parameters_problem(pair, p),
            "the transmission error's compliance needs the model torque input");
}

// The second pair is the first pair's maths at its own rate f_2: sin/cos(f_2 (x + τ / k)); at
// f_2 = 0 (a joint without a second order) both inputs are 0.
TEST(ExogenousInputs, SecondPairAtItsOwnRateAndRefusedWithoutARate) {
  ExogenousParameters p;
  p.transmission_error_rad_per_rad = 160.0;
  p.transmission_error_2_rad_per_rad = 400.0;
  p.transmission_error_compliance_rad_per_nm = 2e-6;
  const ExogenousSample s{0.3, 0.0, 50.0};
  const double motor = 0.3 + 2e-6 * 50.0;
  EXPECT_DOUBLE_EQ(exogenous_value(TableInput::kTransmissionError2Sin, p, s),
                   std::sin(400.0 * motor));
  EXPECT_DOUBLE_EQ(exogenous_value(TableInput::kTransmissionError2Cos, p, s),
                   std::cos(400.0 * motor));
  EXPECT_DOUBLE_EQ(exogenous_value(TableInput::kTransmissionErrorSin, p, s),
                   std::sin(160.0 * motor));
  const std::vector<TableInput> both = {TableInput::kModelTorque, TableInput::kTransmissionErrorSin,
                                        TableInput::kTransmissionErrorCos,
                                        TableInput::kTransmissionError2Sin,
                                        TableInput::kTransmissionError2Cos};
  EXPECT_EQ(exogenous_parameters_problem(both, p), "");
  p.transmission_error_2_rad_per_rad = 160.0;  // the first's rate: the pairs would be one
  EXPECT_NE(exogenous_parameters_problem(both, p), "");
  // 0: the joint has no second order; both of the pair's inputs are 0 (a zero cos too).
  p.transmission_error_2_rad_per_rad = 0.0;
  EXPECT_EQ(exogenous_parameters_problem(both, p), "");
  EXPECT_EQ(exogenous_value(TableInput::kTransmissionError2Sin, p, s), 0.0);
  EXPECT_EQ(exogenous_value(TableInput::kTransmissionError2Cos, p, s), 0.0);
  p.transmission_error_2_rad_per_rad = -400.0;
  EXPECT_NE(exogenous_parameters_problem(both, p), "");
}

}  // namespace
}  // namespace imscal::ident
