// The transmission error's orders found by order tracking (eval/
// transmission_error_order_spectrum.hpp), checked against a synthetic record whose truth is
// known: a joint swept back and forth at several steady speeds through a gear of ratio 100, its
// error the sum of two orders (3″ at 2 and 1.5″ at 3.5 per motor revolution), a slow
// gravity-like term, a 3 Hz oscillation of the path's dynamics (not tied to the motor angle) and
// white noise; a second joint with the same motion and error but no transmission error.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "eval/transmission_error_order_spectrum.hpp"

namespace imscal::eval {
namespace {

constexpr double kArcsecRad = std::numbers::pi / 180.0 / 3600.0;
constexpr double kRatio = 100.0;

// Joint speed profile: steady stretches of 2 s at 0.2 .. 0.8 rad/s, each way, joined by 0.3 s
// ramps; the motor then turns at 3.2 .. 12.7 rev/s.
ident::JointErrorLog synthetic_log() {
  ident::JointErrorLog log;
  log.robot = "synthetic";
  log.cycle_s = 0.002;
  log.joint_names = {"A1", "A2"};
  log.q_desired_rad.assign(2, {});
  log.q_measured_rad.assign(2, {});
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.5 * kArcsecRad);
  const std::vector<double> speeds{0.2, 0.4, 0.6, 0.8};
  double q = 0.0, t = 0.0;
  for (int sweep = 0; sweep < 3; ++sweep)
    for (double v : speeds)
      for (double sign : {1.0, -1.0}) {
        for (double s = 0.0; s < 2.6; s += log.cycle_s) {
          const double ramp = std::min({1.0, s / 0.3, (2.6 - s) / 0.3});
          q += sign * v * ramp * log.cycle_s;
          t += log.cycle_s;
          const double theta = kRatio * q;
          const double rest =
              2e-4 * std::cos(q) + 5.0 * kArcsecRad * std::sin(2 * 3.0 * std::numbers::pi * t);
          const double te = 3.0 * kArcsecRad * std::sin(2.0 * theta + 0.4) +
                            1.5 * kArcsecRad * std::sin(3.5 * theta + 2.0);
          log.time_s.push_back(t);
          log.payload_kg.push_back(0.0);
          for (std::size_t j = 0; j < 2; ++j) {
            log.q_desired_rad[j].push_back(q);
            log.q_measured_rad[j].push_back(q - rest - (j == 0 ? te : 0.0) - noise(rng));
          }
        }
      }
  return log;
}

TEST(TransmissionErrorOrderSpectrum, FindsBothOrdersAndTheirAmplitudes) {
  const std::vector<JointOrderSpectrum> spectra =
      transmission_error_order_spectra(synthetic_log(), {kRatio, kRatio});
  ASSERT_EQ(spectra.size(), 2U);
  const JointOrderSpectrum& a1 = spectra[0];
  ASSERT_EQ(a1.significant.size(), 2U);
  EXPECT_EQ(a1.significant[0].order, 2.0);
  EXPECT_EQ(a1.significant[1].order, 3.5);
  // The amplitude is the windows' RMS of the Hann-weighted Fourier amplitude: within 10 % of the
  // truth (a window spans a little more than 8 motor revolutions, and the detrending and the
  // noise take a little).
  EXPECT_NEAR(a1.significant[0].amplitude_rad / kArcsecRad, 3.0, 0.3);
  EXPECT_NEAR(a1.significant[1].amplitude_rad / kArcsecRad, 1.5, 0.15);
  EXPECT_GT(a1.windows, 20U);
}

TEST(TransmissionErrorOrderSpectrum, AJointWithoutTransmissionErrorHasNoSignificantOrder) {
  const std::vector<JointOrderSpectrum> spectra =
      transmission_error_order_spectra(synthetic_log(), {kRatio, kRatio});
  EXPECT_TRUE(spectra[1].significant.empty()) << describe_order_spectrum(spectra[1]);
  EXPECT_EQ(spectra[1].windows, spectra[0].windows);
}

TEST(TransmissionErrorOrderSpectrum, AJointWithoutGearRatioHasNoSpectrum) {
  const std::vector<JointOrderSpectrum> spectra =
      transmission_error_order_spectra(synthetic_log(), {kRatio});
  EXPECT_EQ(spectra[1].windows, 0U);
  EXPECT_TRUE(spectra[1].lines.empty());
}

TEST(TransmissionErrorOrderSpectrum, RefusesOptionsOutOfRange) {
  OrderSpectrumOptions options;
  options.window_motor_revs = 0.0;
  EXPECT_THROW(transmission_error_order_spectra(synthetic_log(), {kRatio, kRatio}, options),
               std::invalid_argument);
}

}  // namespace
}  // namespace imscal::eval
