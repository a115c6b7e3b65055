// SplineTrajectory: sampling an analytic motion at 1 kHz and interpolating reproduces its p, v,
// a, attitude and omega between the samples, and the IMS increments synthesised from it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#include "ims/analytic_trajectory.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/so3.hpp"
#include "ims/spline_trajectory.hpp"

using namespace imscal::ims;

namespace {
bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

std::vector<PoseSample> sample(const Trajectory& traj, double rate_hz) {
  std::vector<PoseSample> out;
  const auto n =
      static_cast<std::size_t>(std::floor((traj.end_s() - traj.begin_s()) * rate_hz + 1e-9));
  for (std::size_t k = 0; k <= n; ++k) {
    const double t = traj.begin_s() + k / rate_hz;
    const KinematicState s = traj.at(t);
    out.push_back({t, s.p_W, s.q_W_S});
  }
  return out;
}

// Random moves; 30 s (10 s under the sanitizers, which are ~10x slower).
std::unique_ptr<AnalyticTrajectory> test_motion() {
  return make_motion_with_pauses(sanitized() ? 10.0 : 30.0, 4.0, 21);
}
}  // namespace

TEST(SplineTrajectory, ReproducesAnalyticMotionBetweenSamples) {
  const auto truth = test_motion();
  const SplineTrajectory spline(sample(*truth, 1000.0));
  EXPECT_EQ(spline.begin_s(), truth->begin_s());
  EXPECT_DOUBLE_EQ(spline.end_s(), truth->end_s());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> when(truth->begin_s(), truth->end_s());
  double err_p = 0, err_q = 0, err_v = 0, err_w = 0, err_a = 0;
  for (int i = 0; i < 20000; ++i) {
    const double t = i < 10 ? truth->begin_s() + 1e-4 * i : when(rng);  // also near the ends
    const KinematicState a = truth->at(t);
    const KinematicState b = spline.at(t);
    err_p = std::max(err_p, (a.p_W - b.p_W).norm());
    err_q = std::max(err_q, rotation_angle_between(a.q_W_S, b.q_W_S));
    err_v = std::max(err_v, (a.v_W - b.v_W).norm());
    err_w = std::max(err_w, (a.omega_WS_S - b.omega_WS_S).norm());
    err_a = std::max(err_a, (a.a_W - b.a_W).norm());
  }
  // The analytic motion is only C^4 at the ends of its smooth steps: a stencil across such a
  // joint sees the jump J of the fifth derivative (J ~ 1.5e4 * 1 m / T^5 ~ 1e4..1e5 m/s^5 for
  // T ~ 0.7..1 s) and errs by ~ J h^3 / 100 in a, J h^4 / 100 in v and omega (h = 1 ms):
  // ~1e-7 m/s^2 and ~1e-10. Elsewhere only rounding remains (see the smooth test below).
  EXPECT_LT(err_p, 1e-12) << "position [m]";
  EXPECT_LT(err_q, 1e-12) << "attitude [rad]";
  EXPECT_LT(err_v, 1e-9) << "velocity [m/s]";
  EXPECT_LT(err_w, 1e-9) << "rate [rad/s]";
  EXPECT_LT(err_a, 1e-6) << "acceleration [m/s^2]";
  std::printf("max errors: p %.2e m, q %.2e rad, v %.2e m/s, omega %.2e rad/s, a %.2e m/s^2\n",
              err_p, err_q, err_v, err_w, err_a);
}

namespace {
// A motion smooth everywhere (C^infinity): sinusoidal translation, rotation about one fixed axis
// by theta(t) = 1.5 t + 0.3 sin(2 t), so omega_WS_S = u dtheta/dt.
class SmoothMotion : public Trajectory {
 public:
  double begin_s() const override { return 0.0; }
  double end_s() const override { return 5.0; }
  KinematicState at(double t) const override {
    KinematicState s;
    const Eigen::Vector3d u = Eigen::Vector3d(1, 2, 2) / 3.0;
    s.q_W_S = Eigen::Quaterniond(Eigen::AngleAxisd(1.5 * t + 0.3 * std::sin(2 * t), u));
    s.omega_WS_S = u * (1.5 + 0.6 * std::cos(2 * t));
    s.p_W = Eigen::Vector3d(0.3 * std::sin(2 * t), 0.2 * std::cos(3 * t), 0.1 * std::sin(t));
    s.v_W = Eigen::Vector3d(0.6 * std::cos(2 * t), -0.6 * std::sin(3 * t), 0.1 * std::cos(t));
    s.a_W = Eigen::Vector3d(-1.2 * std::sin(2 * t), -1.8 * std::cos(3 * t), -0.1 * std::sin(t));
    return s;
  }
};
}  // namespace

TEST(SplineTrajectory, RoundingLevelOnSmoothMotion) {
  const SmoothMotion truth;
  const SplineTrajectory spline(sample(truth, 1000.0));
  double err_p = 0, err_q = 0, err_v = 0, err_w = 0, err_a = 0;
  for (double t = 0.0; t <= 5.0; t += 0.000737) {
    const KinematicState a = truth.at(t);
    const KinematicState b = spline.at(t);
    err_p = std::max(err_p, (a.p_W - b.p_W).norm());
    err_q = std::max(err_q, rotation_angle_between(a.q_W_S, b.q_W_S));
    err_v = std::max(err_v, (a.v_W - b.v_W).norm());
    err_w = std::max(err_w, (a.omega_WS_S - b.omega_WS_S).norm());
    err_a = std::max(err_a, (a.a_W - b.a_W).norm());
  }
  // Truncation: 7-point stencils, derivatives of order 7 ~ 3^7 * 0.2 = 440: v ~ h^6 * 440 / 140
  // ~ 3e-18, a ~ h^5 * 440 / 100 ~ 4e-15. Rounding of the samples (1e-16 m, 1e-16 rad) times
  // the stencil weights: ~3e-13 in v and omega (~3e-12 with the one-sided stencils at the
  // ends and the log map's own rounding), ~1e-9 in a.
  EXPECT_LT(err_p, 1e-14) << "position [m]";
  EXPECT_LT(err_q, 1e-14) << "attitude [rad]";
  EXPECT_LT(err_v, 1e-12) << "velocity [m/s]";
  EXPECT_LT(err_w, 1e-11) << "rate [rad/s]";
  EXPECT_LT(err_a, 1e-8) << "acceleration [m/s^2]";
  std::printf(
      "smooth motion, max errors: p %.2e m, q %.2e rad, v %.2e m/s, omega %.2e rad/s, "
      "a %.2e m/s^2\n",
      err_p, err_q, err_v, err_w, err_a);
}

TEST(SplineTrajectory, SynthesisedIncrementsMatchAnalytic) {
  const EarthModel earth(Site{48.78, 9.18, 300.0});
  const auto truth = test_motion();
  const SplineTrajectory spline(sample(*truth, 1000.0));
  // 1 kHz: IMS samples on the knots; 400 Hz: knots inside the intervals (quadrature split).
  for (double rate : {1000.0, 400.0}) {
    const ImuSeries a = synthesize_ideal_increments(*truth, earth, rate);
    const ImuSeries b = synthesize_ideal_increments(spline, earth, rate);
    ASSERT_EQ(a.samples.size(), b.samples.size());
    double err_g = 0, err_v = 0;
    for (std::size_t k = 0; k < a.samples.size(); ++k) {
      err_g = std::max(err_g, (a.samples[k].gyro - b.samples[k].gyro).norm());
      err_v = std::max(err_v, (a.samples[k].acc - b.samples[k].acc).norm());
    }
    // The bounds on omega and a above, integrated over one interval (1 or 2.5 ms).
    EXPECT_LT(err_g, 1e-9 / rate) << rate << " Hz, gyro [rad]";
    EXPECT_LT(err_v, 1e-6 / rate) << rate << " Hz, acc [m/s]";
  }
}

TEST(SplineTrajectory, RejectsBadSamples) {
  const auto truth = make_roundtrip_test_motion();
  auto samples = sample(*truth, 100.0);
  EXPECT_THROW(SplineTrajectory(std::vector<PoseSample>(samples.begin(), samples.begin() + 6)),
               std::invalid_argument);
  auto reversed = samples;
  reversed[10].t_s = reversed[9].t_s;
  EXPECT_THROW(SplineTrajectory{reversed}, std::invalid_argument);
  // At 2 Hz the 3 rad/s rotations move ~1 rad between samples: too sparse.
  EXPECT_THROW(SplineTrajectory{sample(*truth, 2.0)}, std::invalid_argument);
}
