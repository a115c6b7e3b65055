// The joint-space signatures of IMS-chain errors (eval/gap_signals.hpp ims_chain_columns)
// against the exact chain: the flange pose the chain would measure with the error, through the
// nominal model's inverse kinematics (Newton to 1e-12 rad, tests/eval/gap_cases.hpp
// solve_near). The signatures are first order, so for small errors they must agree to second
// order; and their candidates recover an injected error's parameters.
#include <gtest/gtest.h>

#include <cmath>

#include "eval/gap_candidates.hpp"
#include "tests/eval/gap_cases.hpp"

namespace imscal::eval {
namespace {

// A 4 s path of all six joints (sums of sines about a pose away from the singularities), 2 ms.
struct Path {
  std::vector<std::vector<double>> q, qd;
  std::vector<double> t;
};
Path test_path() {
  Path p;
  const std::size_t n = 2000;
  const double home[6] = {0.3, -1.2, 1.4, 0.4, 0.9, -0.5};
  p.q.assign(6, std::vector<double>(n));
  p.qd = p.q;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = 0.002 * double(k);
    p.t.push_back(t);
    for (std::size_t j = 0; j < 6; ++j) {
      const double w = 2.0 * M_PI * (0.2 + 0.07 * double(j));
      p.q[j][k] = home[j] + 0.4 * std::sin(w * t + double(j));
      p.qd[j][k] = 0.4 * w * std::cos(w * t + double(j));
    }
  }
  return p;
}

calib::JointVector at(const Path& p, std::size_t k) {
  calib::JointVector q;
  for (int j = 0; j < 6; ++j) q[j] = p.q[std::size_t(j)][k];
  return q;
}

class ChainSignatures : public ::testing::Test {
 protected:
  calib::RobotDescription robot =
      calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml");
  Path path = test_path();
  std::vector<GapSignals::ImsChainColumns> columns =
      ims_chain_columns(robot.kinematics, path.q, path.qd, path.t);

  // Max over joints and samples of |predicted - exact| relative to max |exact|; `target` gives
  // the measured flange pose at sample k, `predicted` the signature's gap of joint j at k.
  template <typename Target, typename Predicted>
  double relative_error(Target target, Predicted predicted) {
    double worst = 0.0, largest = 0.0;
    for (std::size_t k = 0; k < path.t.size(); k += 50) {
      const calib::JointVector q = at(path, k);
      const calib::JointVector qm = test::solve_near(robot.kinematics, target(k), q);
      for (std::size_t j = 0; j < 6; ++j) {
        const double exact = -(qm[long(j)] - q[long(j)]);  // the gap: q_d - q_m minus (q_d - q)
        largest = std::max(largest, std::abs(exact));
        worst = std::max(worst, std::abs(predicted(j, k) - exact));
      }
    }
    return worst / largest;
  }
};

TEST_F(ChainSignatures, DhErrorMatchesTheExactInverseKinematics) {
  // a of link 2 (the upper arm) 0.1 mm longer, alpha of link 4 0.2 mrad: second-order terms are
  // ~1e-4 of the first-order gap (error / lever ~ 1e-4); 1e-3 allows for the damping 1e-3 of the
  // Jacobian inverse, which is ~1e-6 relative away from singularities.
  calib::KinematicModel real = robot.kinematics;
  real.dh[1].a_m += 1e-4;
  real.dh[3].alpha_rad += 2e-4;
  const double err = relative_error(
      [&](std::size_t k) { return calib::forward_kinematics<double>(real, at(path, k)); },
      [&](std::size_t j, std::size_t k) {
        return columns[j].dh(long(k), 3) * 1e-4 + columns[j].dh(long(k), 10) * 2e-4;
      });
  EXPECT_LT(err, 1e-3);
}

TEST_F(ChainSignatures, MountingErrorMatchesTheExactChain) {
  // D: 0.5 mrad about (1, 2, -1)/sqrt 6 and 0.2 mm along (0, 1, 1)/sqrt 2, in the flange.
  const Eigen::Vector3d r = 5e-4 * Eigen::Vector3d(1, 2, -1).normalized();
  const Eigen::Vector3d t = 2e-4 * Eigen::Vector3d(0, 1, 1).normalized();
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  D.linear() = test::rotation_exp(r);
  D.translation() = t;
  const Eigen::Isometry3d T0 = calib::forward_kinematics<double>(robot.kinematics, at(path, 0));
  // Second order in 5e-4: ~1e-3 relative.
  const double err = relative_error(
      [&](std::size_t k) {
        return Eigen::Isometry3d(T0 * D * T0.inverse() *
                                 calib::forward_kinematics<double>(robot.kinematics, at(path, k)) *
                                 D.inverse());
      },
      [&](std::size_t j, std::size_t k) {
        const auto& m = columns[j].mounting;
        return m.row(long(k)).dot((Eigen::Matrix<double, 6, 1>() << t, r).finished());
      });
  EXPECT_LT(err, 3e-3);
}

TEST_F(ChainSignatures, GyroBiasAndScaleMatchTheIntegratedAttitude) {
  const Eigen::Vector3d bias(2e-5, -1e-5, 3e-5);     // rad/s about the flange axes
  const Eigen::Vector3d scale(1e-3, -2e-3, 1.5e-3);  // per flange axis
  for (const bool use_bias : {true, false}) {
    // The attitude the chain integrates from the flange's rotation increments (as the harness).
    std::vector<Eigen::Matrix3d> attitude(path.t.size());
    Eigen::Matrix3d previous =
        calib::forward_kinematics<double>(robot.kinematics, at(path, 0)).linear();
    attitude[0] = previous;
    for (std::size_t k = 1; k < path.t.size(); ++k) {
      const Eigen::Matrix3d R =
          calib::forward_kinematics<double>(robot.kinematics, at(path, k)).linear();
      const Eigen::AngleAxisd step(previous.transpose() * R);
      Eigen::Vector3d phi = step.angle() * step.axis();
      phi += use_bias ? Eigen::Vector3d(bias * 0.002) : Eigen::Vector3d(scale.cwiseProduct(phi));
      attitude[k] = attitude[k - 1] * test::rotation_exp(phi);
      previous = R;
    }
    // 1 %: the signature integrates the rates by the trapezoid rule from q̇_d, the chain by
    // rotation increments (O(dt) apart at the start of the record), and second order ~1e-3.
    const double err = relative_error(
        [&](std::size_t k) {
          Eigen::Isometry3d T = calib::forward_kinematics<double>(robot.kinematics, at(path, k));
          T.linear() = attitude[k];
          return T;
        },
        [&](std::size_t j, std::size_t k) {
          return use_bias ? columns[j].gyro_bias.row(long(k)).dot(bias)
                          : columns[j].gyro_scale.row(long(k)).dot(scale);
        });
    EXPECT_LT(err, 1e-2) << (use_bias ? "bias" : "scale");
  }
}

}  // namespace
}  // namespace imscal::eval
