// The transmission error through the gear mode: the per-sample pair of ident/exogenous_inputs.hpp
// against an independent truth, the mode's ODE y'' + 2 ζ ω y' + ω² y = ω² d(t) integrated by
// RK4 from rest under the displacement d = sin φ (or cos φ), φ = f x, x = x0 + v t, until its
// transient has decayed; and the mode's frequency and damping from inertia, stiffness and the
// nominal drive (eval/transmission_error_gear_mode.hpp) against their closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "eval/transmission_error_gear_mode.hpp"
#include "ident/exogenous_inputs.hpp"

namespace {
namespace ident = imscal::ident;
using ident::TableInput;

constexpr double kMode_rad_s = 2.0 * std::numbers::pi * 15.0;  // the KR 16's ~15 Hz
constexpr double kDamping = 0.05;
constexpr double kPhaseRate = 160.0;  // order 1 x gear ratio 160

// The ODE's response at time t_end to the displacement d(t) = sin φ(t) (or cos), from rest.
double simulated_response(double speed_rad_s, double x0_rad, double t_end_s, bool sine) {
  const double w = kMode_rad_s, z = kDamping, dt = 1e-5;
  auto drive = [&](double t) {
    const double phase = kPhaseRate * (x0_rad + speed_rad_s * t);
    return sine ? std::sin(phase) : std::cos(phase);
  };
  auto accel = [&](double t, double y, double v) {
    return w * w * (drive(t) - y) - 2.0 * z * w * v;
  };
  double y = 0.0, v = 0.0, t = 0.0;
  const long steps = std::lround(t_end_s / dt);
  for (long i = 0; i < steps; ++i, t = double(i) * dt) {
    const double k1y = v, k1v = accel(t, y, v);
    const double k2y = v + 0.5 * dt * k1v, k2v = accel(t + 0.5 * dt, y + 0.5 * dt * k1y, k2y);
    const double k3y = v + 0.5 * dt * k2v, k3v = accel(t + 0.5 * dt, y + 0.5 * dt * k2y, k3y);
    const double k4y = v + dt * k3v, k4v = accel(t + dt, y + dt * k3y, k4y);
    y += dt / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y);
    v += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
  }
  return y;
}

TEST(TransmissionErrorGearMode, PairIsTheModesSteadyStateResponse) {
  ident::ExogenousParameters p;
  p.transmission_error_rad_per_rad = kPhaseRate;
  p.transmission_error_mode_rad_s = kMode_rad_s;
  p.transmission_error_mode_damping = kDamping;
  // 12 decay times 1 / (ζ ω): the transient is e^-12 ≈ 6e-6 of its start.
  const double settle_s = 12.0 / (kDamping * kMode_rad_s);
  // Below, at and above the resonance, and moving backwards (Ω < 0).
  for (const double ratio : {0.5, 0.9, 1.0, 1.3, -1.3, 3.0}) {
    const double speed = ratio * kMode_rad_s / kPhaseRate, x0 = 0.1;
    const double gain = std::abs(ident::gear_mode_response(p, kPhaseRate, speed));
    for (const double extra_s : {0.0, 0.0123}) {
      const double t = settle_s + extra_s;
      const ident::ExogenousSample s{x0 + speed * t, speed, 0.0};
      for (const bool sine : {true, false}) {
        const TableInput input =
            sine ? TableInput::kTransmissionErrorModeSin : TableInput::kTransmissionErrorModeCos;
        // Tolerance: 1e-3 of the response's amplitude (transient ~6e-6, RK4 with Ω dt ≤ 3e-3
        // far below).
        EXPECT_NEAR(ident::exogenous_value(input, p, s), simulated_response(speed, x0, t, sine),
                    1e-3 * gain)
            << "Ω/ω " << ratio << (sine ? " sin" : " cos");
      }
    }
    if (ratio == 1.0) {
      EXPECT_NEAR(gain, 1.0 / (2.0 * kDamping), 1e-12);  // |H| at resonance
    }
  }
}

TEST(TransmissionErrorGearMode, WithoutAModeThePairIsPlainAndTheSecondOrderHasItsOwnFrequency) {
  ident::ExogenousParameters p;
  p.transmission_error_rad_per_rad = kPhaseRate;
  p.transmission_error_2_rad_per_rad = 2.0 * kPhaseRate;
  const ident::ExogenousSample s{0.37, 0.4, 0.0};
  EXPECT_EQ(ident::exogenous_value(TableInput::kTransmissionErrorSin, p, s),
            std::sin(kPhaseRate * 0.37));
  EXPECT_EQ(ident::exogenous_value(TableInput::kTransmissionError2Cos, p, s),
            std::cos(2.0 * kPhaseRate * 0.37));
  // With a mode, the second pair sees H at its own frequency 2 f v.
  p.transmission_error_mode_rad_s = kMode_rad_s;
  p.transmission_error_mode_damping = kDamping;
  const std::complex<double> h2 = ident::gear_mode_response(p, 2.0 * kPhaseRate, 0.4);
  const double phase2 = 2.0 * kPhaseRate * 0.37;
  EXPECT_NEAR(ident::exogenous_value(TableInput::kTransmissionError2ModeCos, p, s),
              (h2 * std::polar(1.0, phase2)).real(), 1e-12);
  // The plain pairs stay plain beside a mode.
  EXPECT_EQ(ident::exogenous_value(TableInput::kTransmissionError2Cos, p, s), std::cos(phase2));
  // The gear-mode pair's constants pass the check; a mode without damping does not, nor a mode
  // without a gear-mode pair.
  const TableInput pair[] = {TableInput::kTransmissionErrorModeSin,
                             TableInput::kTransmissionErrorModeCos};
  const TableInput plain_pair[] = {TableInput::kTransmissionErrorSin,
                                   TableInput::kTransmissionErrorCos};
  EXPECT_EQ(ident::exogenous_parameters_problem(pair, p), "");
  EXPECT_NE(ident::exogenous_parameters_problem(plain_pair, p), "");
  p.transmission_error_mode_damping = 0.0;
  EXPECT_NE(ident::exogenous_parameters_problem(pair, p), "");
}

TEST(TransmissionErrorGearMode, ModeFromInertiaStiffnessAndTheNominalDamping) {
  imscal::calib::DriveParameters drive;  // kr16.yaml's A1: 15 Hz at 45 kg m^2, 5 % damping
  drive.stiffness_nm_per_rad = 4.0e5;
  drive.damping_nm_s_per_rad = 430.0;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto nominal = imscal::eval::gear_mode_of(45.0, nan, nan, drive);
  EXPECT_FALSE(nominal.stiffness_from_data);
  EXPECT_DOUBLE_EQ(nominal.natural_frequency_rad_s, std::sqrt(4.0e5 / 45.0));
  EXPECT_DOUBLE_EQ(nominal.damping_ratio, 430.0 / (2.0 * std::sqrt(4.0e5 * 45.0)));
  EXPECT_NEAR(nominal.natural_frequency_rad_s / (2.0 * std::numbers::pi), 15.0, 0.05);
  // The data's stiffness where significant and plausible (0.5-2x nominal), else the nominal.
  const auto data = imscal::eval::gear_mode_of(45.0, 3.2e5, 1.0e4, drive);
  EXPECT_TRUE(data.stiffness_from_data);
  EXPECT_DOUBLE_EQ(data.natural_frequency_rad_s, std::sqrt(3.2e5 / 45.0));
  EXPECT_DOUBLE_EQ(data.damping_ratio, nominal.damping_ratio);  // the prior: nominal c, k
  EXPECT_FALSE(imscal::eval::gear_mode_of(45.0, 3.2e5, 1.0e5, drive).stiffness_from_data);
  EXPECT_FALSE(imscal::eval::gear_mode_of(45.0, 1.0e6, 1.0e4, drive).stiffness_from_data);
  // A rigid or undamped nominal drive: no mode.
  drive.damping_nm_s_per_rad = 0.0;
  EXPECT_EQ(imscal::eval::gear_mode_of(45.0, nan, nan, drive).natural_frequency_rad_s, 0.0);
}

}  // namespace
