// Ideal IMS synthesis against closed forms: at rest, constant rotation about one axis, constant
// acceleration (each with its own small Trajectory written here, independent of
// AnalyticTrajectory); exactness of the quadrature on the analytic test motion.
#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "ims/analytic_trajectory.hpp"
#include "ims/imu_file.hpp"
#include "ims/imu_noise.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/nav_trajectory_io.hpp"
#include "ims/so3.hpp"

using namespace imscal::ims;

namespace {
const Site kSite{48.78, 9.18, 300.0};

// Rotation at a constant rate omega about z of S, at rest at p0: q(t) = q0 exp(z omega t).
class ConstantRotation : public Trajectory {
 public:
  ConstantRotation(const Eigen::Quaterniond& q0, const Eigen::Vector3d& p0, double omega)
      : q0_(q0), p0_(p0), omega_(omega) {}
  double begin_s() const override { return 0.0; }
  double end_s() const override { return 2.0; }
  KinematicState at(double t) const override {
    KinematicState s;
    s.q_W_S = q0_ * Eigen::Quaterniond(Eigen::AngleAxisd(omega_ * t, Eigen::Vector3d::UnitZ()));
    s.p_W = p0_;
    s.omega_WS_S = Eigen::Vector3d(0, 0, omega_);
    return s;
  }

 private:
  Eigen::Quaterniond q0_;
  Eigen::Vector3d p0_;
  double omega_;
};

// Constant acceleration a from p0, v0 at a fixed attitude q0.
class ConstantAcceleration : public Trajectory {
 public:
  ConstantAcceleration(const Eigen::Quaterniond& q0, const Eigen::Vector3d& p0,
                       const Eigen::Vector3d& v0, const Eigen::Vector3d& a)
      : q0_(q0), p0_(p0), v0_(v0), a_(a) {}
  double begin_s() const override { return 0.0; }
  double end_s() const override { return 1.0; }
  KinematicState at(double t) const override {
    KinematicState s;
    s.q_W_S = q0_;
    s.p_W = p0_ + v0_ * t + 0.5 * a_ * t * t;
    s.v_W = v0_ + a_ * t;
    s.a_W = a_;
    return s;
  }
  Eigen::Quaterniond q0_;
  Eigen::Vector3d p0_, v0_, a_;
};

const Eigen::Quaterniond kAttitude = quat_exp(Eigen::Vector3d(0.4, -1.1, 2.0));
}  // namespace

TEST(ImuSynthesis, AtRestIsEarthRateAndGravity) {
  const EarthModel earth(kSite);
  const Eigen::Vector3d p(0.3, -0.2, 0.7);
  const AnalyticTrajectory still(0.0, 0.5, kAttitude, p);  // no steps: at rest
  const ImuSeries series = synthesize_ideal_increments(still, earth, 1000.0);
  ASSERT_EQ(series.samples.size(), 500u);
  EXPECT_EQ(series.quantity, ImuQuantity::kIncrements);
  EXPECT_DOUBLE_EQ(series.samples.front().t_s, 0.001);
  EXPECT_DOUBLE_EQ(series.samples.back().t_s, 0.5);
  ASSERT_TRUE(series.site.has_value());
  const Eigen::Matrix3d R_S_W = kAttitude.conjugate().toRotationMatrix();
  const Eigen::Vector3d rate = R_S_W * earth.earth_rate_W();
  const Eigen::Vector3d force = -R_S_W * earth.gravity_W(p);
  double t_prev = 0.0;
  for (const ImuSample& s : series.samples) {
    // The interval between the stamps as represented (k / 1000 rounds: 1 ms +- 1e-16 s).
    const double dt = s.t_s - t_prev;
    t_prev = s.t_s;
    // Constant integrand: the weights sum to 2, so only the rounding of 16 weighted terms
    // (a few ulp each) remains; 1e-14 relative.
    EXPECT_LT((s.gyro - rate * dt).norm(), 1e-14 * rate.norm() * dt);
    EXPECT_LT((s.acc - force * dt).norm(), 1e-14 * force.norm() * dt);
  }
  const ImuSeries rates = synthesize_ideal_rates(still, earth, 100.0);
  ASSERT_EQ(rates.samples.size(), 51u);
  EXPECT_EQ(rates.samples.front().t_s, 0.0);
  EXPECT_LT((rates.samples[7].gyro - rate).norm(), 1e-15 * rate.norm());  // no quadrature
  EXPECT_LT((rates.samples[7].acc - force).norm(), 1e-15 * force.norm());
}

TEST(ImuSynthesis, ConstantRotationClosedForm) {
  const EarthModel earth(kSite);
  const double omega = 2.5;  // [rad/s] about z of S
  const Eigen::Vector3d p(0.1, 0.2, -0.3);
  const ConstantRotation traj(kAttitude, p, omega);
  const double rate_hz = 200.0;
  const ImuSeries series = synthesize_ideal_increments(traj, earth, rate_hz);
  ASSERT_EQ(series.samples.size(), 400u);
  // R_S_W(t) = Rz(-omega t) R0^T; integral of Rz(-omega t) over (t0, t1] in closed form, with
  // sum-to-product identities so that no digits cancel.
  const Eigen::Matrix3d R0T = kAttitude.conjugate().toRotationMatrix();
  double t0 = 0.0;
  for (const ImuSample& s : series.samples) {
    const double t1 = s.t_s;
    const double mid = 0.5 * omega * (t0 + t1), half = 0.5 * omega * (t1 - t0);
    const double int_cos = 2.0 * std::cos(mid) * std::sin(half) / omega;  // int cos(omega t)
    const double int_sin = 2.0 * std::sin(mid) * std::sin(half) / omega;  // int sin(omega t)
    Eigen::Matrix3d M;
    M << int_cos, int_sin, 0, -int_sin, int_cos, 0, 0, 0, t1 - t0;
    const Eigen::Vector3d dtheta =
        Eigen::Vector3d(0, 0, omega * (t1 - t0)) + M * R0T * earth.earth_rate_W();
    const Eigen::Vector3d dv = -M * R0T * earth.gravity_W(p);
    // The integrand is a trigonometric polynomial of frequency omega: 8-point Gauss-Legendre
    // over omega h = 0.0125 rad is exact far below rounding; allow 1e-14 relative (rounding of
    // the sums and of the closed form).
    EXPECT_LT((s.gyro - dtheta).norm(), 1e-14 * dtheta.norm()) << "t " << t1;
    EXPECT_LT((s.acc - dv).norm(), 1e-14 * dv.norm()) << "t " << t1;
    t0 = t1;
  }
}

TEST(ImuSynthesis, ConstantAccelerationClosedForm) {
  const EarthModel earth(kSite);
  const ConstantAcceleration traj(kAttitude, Eigen::Vector3d(0.2, 0.1, 0.0),
                                  Eigen::Vector3d(0.5, -1.0, 0.25),
                                  Eigen::Vector3d(1.5, 0.8, -2.0));
  const ImuSeries series = synthesize_ideal_increments(traj, earth, 100.0);
  ASSERT_EQ(series.samples.size(), 100u);
  const Eigen::Matrix3d R_S_W = kAttitude.conjugate().toRotationMatrix();
  const Eigen::Vector3d& W = earth.earth_rate_W();
  const Eigen::Matrix3d& G = earth.gravity_gradient_W();
  const Eigen::Vector3d& g0 = earth.gravity_origin_W();
  double t0 = 0.0;
  for (const ImuSample& s : series.samples) {
    const double t1 = s.t_s;
    // f_W(t) = a + 2 W x (v0 + a t) - g0 - G (p0 + v0 t + a t^2 / 2): a quadratic in t.
    const double i1 = t1 - t0, i2 = (t1 * t1 - t0 * t0) / 2, i3 = (t1 * t1 * t1 - t0 * t0 * t0) / 6;
    const Eigen::Vector3d f_int = (traj.a_ + 2 * W.cross(traj.v0_) - g0 - G * traj.p0_) * i1 +
                                  (2 * W.cross(traj.a_) - G * traj.v0_) * i2 - G * traj.a_ * i3;
    const Eigen::Vector3d dv = R_S_W * f_int;
    const Eigen::Vector3d dtheta = R_S_W * W * i1;
    EXPECT_LT((s.acc - dv).norm(), 1e-14 * dv.norm()) << "t " << t1;  // polynomial: exact
    EXPECT_LT((s.gyro - dtheta).norm(), 1e-15 * dtheta.norm()) << "t " << t1;
    t0 = t1;
  }
}

TEST(ImuSynthesis, QuadratureIsExactOnTheTestMotion) {
  // Two 1 ms increments must add up to the 2 ms increment over the same span: both are exact
  // integrals if the quadrature is. Any quadrature error (which grows like h^17 away from the
  // C^4 joints, like h^6 at them) would show as a mismatch far above rounding.
  const EarthModel earth(kSite);
  const auto traj = make_roundtrip_test_motion();
  // 512 and 256 Hz: most ends of the smooth steps (multiples of 0.1 s) fall inside intervals.
  const ImuSeries fine = synthesize_ideal_increments(*traj, earth, 512.0);
  const ImuSeries coarse = synthesize_ideal_increments(*traj, earth, 256.0);
  ASSERT_EQ(fine.samples.size(), 2 * coarse.samples.size());
  double worst_gyro = 0.0, worst_acc = 0.0;
  for (std::size_t k = 0; k < coarse.samples.size(); ++k) {
    const ImuSample& c = coarse.samples[k];
    const Eigen::Vector3d g = fine.samples[2 * k].gyro + fine.samples[2 * k + 1].gyro;
    const Eigen::Vector3d a = fine.samples[2 * k].acc + fine.samples[2 * k + 1].acc;
    worst_gyro = std::max(worst_gyro, (g - c.gyro).norm());
    worst_acc = std::max(worst_acc, (a - c.acc).norm());
  }
  // Increments are <= 1.2e-2 rad and ~4e-2 m/s: rounding of sums of 16..32 terms ~ 1e-16.
  EXPECT_LT(worst_gyro, 1e-16) << "worst gyro mismatch [rad]";
  EXPECT_LT(worst_acc, 5e-16) << "worst acc mismatch [m/s]";
  // The total rotation and velocity change over the whole motion in the W frame: integrating
  // the synthesised increments by a first-order rule would not give a closed form, so check
  // instead that the accelerometer sees gravity at the final rest exactly.
  const KinematicState end = traj->at(traj->end_s());
  const double last_dt = fine.samples.back().t_s - fine.samples[fine.samples.size() - 2].t_s;
  const Eigen::Vector3d dv_rest = -(end.q_W_S.conjugate() * earth.gravity_W(end.p_W)) * last_dt;
  EXPECT_LT((fine.samples.back().acc - dv_rest).norm(), 1e-14 * dv_rest.norm());
}

namespace {
// The same motion without its PiecewiseSmooth interface: the synthesiser cannot split there.
class HiddenJoints : public Trajectory {
 public:
  explicit HiddenJoints(const Trajectory& inner) : inner_(inner) {}
  double begin_s() const override { return inner_.begin_s(); }
  double end_s() const override { return inner_.end_s(); }
  KinematicState at(double t) const override { return inner_.at(t); }

 private:
  const Trajectory& inner_;
};
}  // namespace

TEST(ImuSynthesis, SplittingAtJointsIsWhatMakesItExact) {
  // Without the split, intervals that hold the end of a smooth step (where the third derivative
  // of the specific force jumps) are integrated with an error ~ jump * h^4 / 1e5: the check
  // above would see it. This guards the premise of QuadratureIsExactOnTheTestMotion.
  const EarthModel earth(kSite);
  const auto traj = make_roundtrip_test_motion();
  const HiddenJoints hidden(*traj);
  // 256 Hz: most ends of the smooth steps (multiples of 0.1 s) fall inside intervals.
  const ImuSeries split = synthesize_ideal_increments(*traj, earth, 256.0);
  const ImuSeries plain = synthesize_ideal_increments(hidden, earth, 256.0);
  double worst_acc = 0.0;
  for (std::size_t k = 0; k < split.samples.size(); ++k) {
    worst_acc = std::max(worst_acc, (split.samples[k].acc - plain.samples[k].acc).norm());
  }
  EXPECT_GT(worst_acc, 1e-14) << "unsplit quadrature error [m/s]";
  EXPECT_LT(worst_acc, 1e-9) << "unsplit quadrature error [m/s]";
  std::printf("quadrature error without the split at joints: %.2e m/s at 256 Hz\n", worst_acc);
}

TEST(ImuSynthesis, RejectsBadRates) {
  const EarthModel earth(kSite);
  const AnalyticTrajectory still(0.0, 0.5);
  EXPECT_THROW(synthesize_ideal_increments(still, earth, 0.0), std::invalid_argument);
  EXPECT_THROW(synthesize_ideal_increments(still, earth, 1.0), std::invalid_argument);
}

TEST(ImuSynthesis, CommandWritesWhatTheLibraryMakes) {
  // `imscal synthesize` end to end: its imu.csv must hold exactly the library's output for the
  // same seed (the CSV round trip is bit-exact), its truth files the motion and drawn errors.
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::temp_directory_path() / ("imscal_synth_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::string src = IMSCAL_SOURCE_DIR;
  const std::string command = std::string(IMSCAL_BINARY) + " synthesize --motion " + src +
                              "/datasets/motions/roundtrip-test.yaml --sensor " + src +
                              "/datasets/sensors/navigation-grade.yaml --site 48.78,9.18,300 "
                              "--rate-hz 100 --seed 17 --out " +
                              dir.string() + " 2>/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  // A second run refuses to overwrite (exit code 2: bad input).
  EXPECT_NE(std::system(command.c_str()), 0);

  const EarthModel earth(Site{48.78, 9.18, 300});
  const ImuSeries ideal = synthesize_ideal_increments(*make_roundtrip_test_motion(), earth, 100.0);
  const SensorSpec spec = load_sensor_spec(src + "/datasets/sensors/navigation-grade.yaml");
  std::mt19937_64 rng(17);
  const SensorErrorModel errors = draw_sensor_errors(spec, rng);
  const ImuSeries expected = corrupt(ideal, errors, spec, rng());

  const ImuSeries written = read_imu_file(dir / "imu.csv");
  ASSERT_EQ(written.samples.size(), expected.samples.size());
  for (std::size_t k = 0; k < written.samples.size(); ++k) {
    ASSERT_EQ(written.samples[k].t_s, expected.samples[k].t_s) << k;
    ASSERT_EQ(written.samples[k].gyro, expected.samples[k].gyro) << k;
    ASSERT_EQ(written.samples[k].acc, expected.samples[k].acc) << k;
  }
  ASSERT_TRUE(written.site.has_value());
  EXPECT_EQ(written.site->latitude_deg, 48.78);

  const SensorErrorModel back = load_sensor_error_model(dir / "truth" / "sensor_errors.yaml");
  // 17 significant digits and unit conversions: a few ulp.
  EXPECT_LT((back.gyro.bias - errors.gyro.bias).norm(), 1e-15 * errors.gyro.bias.norm());
  EXPECT_LT((back.acc.misalignment - errors.acc.misalignment).norm(),
            1e-15 * errors.acc.misalignment.norm());
  const NavTrajectory truth = read_trajectory_csv(dir / "truth" / "trajectory.csv");
  ASSERT_EQ(truth.states.size(), expected.samples.size() + 1);  // begin_s and every sample
  const auto motion = make_roundtrip_test_motion();
  for (std::size_t k : {std::size_t{0}, std::size_t{1234}, truth.states.size() - 1}) {
    const KinematicState s = motion->at(truth.states[k].t_s);
    EXPECT_EQ(truth.states[k].p_W, s.p_W);  // shortest round-trip form: bit-exact
    EXPECT_EQ(truth.states[k].v_W, s.v_W);
    EXPECT_LT(rotation_angle_between(truth.states[k].q_W_S, s.q_W_S), 1e-15);  // renormalised
  }
  fs::remove_all(dir);
}
