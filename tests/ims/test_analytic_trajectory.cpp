// AnalyticTrajectory: the analytic v, a and omega_WS_S against finite differences of the
// analytic p and q; the promised properties of the two factories (rests, peaks, end pose);
// the YAML motion loader against a closed-form end pose.
#include <gtest/gtest.h>

#include <random>

#include "core/input_error.hpp"
#include "ims/analytic_trajectory.hpp"
#include "ims/so3.hpp"

using namespace imscal::ims;

namespace {
// Fourth-order central difference of f at t with step h: error h^4 f^(5) / 30.
template <typename F>
Eigen::Vector3d central_difference(F f, double t, double h) {
  return (-f(t + 2 * h) + 8.0 * f(t + h) - 8.0 * f(t - h) + f(t - 2 * h)) / (12.0 * h);
}

void expect_derivatives_consistent(const AnalyticTrajectory& traj, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> when(traj.begin_s() + 0.01, traj.end_s() - 0.01);
  const double h = 1e-3;
  for (int i = 0; i < 400; ++i) {
    const double t = when(rng);
    const KinematicState s = traj.at(t);
    // Motions of ~1 m / ~1 rad over >= 1 s: fifth derivatives are < ~1e4 per s^5, so the
    // truncation error h^4 f^(5) / 30 is < 3e-10; rounding ~ 1e-16 / h = 1e-13. Allow 1e-8.
    const Eigen::Vector3d v_fd = central_difference([&](double x) { return traj.at(x).p_W; }, t, h);
    const Eigen::Vector3d a_fd = central_difference([&](double x) { return traj.at(x).v_W; }, t, h);
    // omega = d/dt log(q(t)^-1 q(t + dt)) at dt = 0: differences in the chart at t.
    const Eigen::Vector3d w_fd = central_difference(
        [&](double x) {
          return quat_log(Eigen::Quaterniond(s.q_W_S.conjugate() * traj.at(x).q_W_S));
        },
        t, h);
    EXPECT_LT((s.v_W - v_fd).norm(), 1e-8) << "t " << t;
    EXPECT_LT((s.a_W - a_fd).norm(), 1e-8) << "t " << t;
    EXPECT_LT((s.omega_WS_S - w_fd).norm(), 1e-8) << "t " << t;
  }
}

struct Peaks {
  Eigen::Vector3d omega_abs = Eigen::Vector3d::Zero();  // per S axis
  double omega = 0.0, accel = 0.0;
};
Peaks peaks(const Trajectory& traj) {
  Peaks p;
  for (double t = traj.begin_s(); t <= traj.end_s(); t += 1e-3) {
    const KinematicState s = traj.at(t);
    p.omega_abs = p.omega_abs.cwiseMax(s.omega_WS_S.cwiseAbs());
    p.omega = std::max(p.omega, s.omega_WS_S.norm());
    p.accel = std::max(p.accel, s.a_W.norm());
  }
  return p;
}
}  // namespace

TEST(SmoothStep, EndsAndSymmetry) {
  const SmoothStep step{1.0, 3.0};
  EXPECT_EQ(step.at(0.5).s, 0.0);
  EXPECT_EQ(step.at(3.5).s, 1.0);
  // Odd symmetry about the middle: s(mid + x) = 1 - s(mid - x); the Bernstein form is
  // accurate to a few ulp.
  for (double x : {0.1, 0.4, 0.77}) EXPECT_NEAR(step.at(2 + x).s, 1 - step.at(2 - x).s, 1e-15);
  EXPECT_NEAR(step.at(2.0).s, 0.5, 1e-15);
  // Against the monomial form u^5 (126 - 420 u + 540 u^2 - 315 u^3 + 70 u^4) in long double.
  for (double u : {0.05, 0.3, 0.5, 0.81, 0.999}) {
    const long double x = u;
    const long double mono =
        x * x * x * x * x * (126 - 420 * x + 540 * x * x - 315 * x * x * x + 70 * x * x * x * x);
    EXPECT_NEAR(step.at(1.0 + 2.0 * u).s, static_cast<double>(mono), 1e-15) << u;
  }
  // Peak slope 630/256 per normalised time, i.e. / 2 s here.
  EXPECT_NEAR(step.at(2.0).ds_dt, SmoothStep::kPeakSlope / 2.0, 1e-14);
}

TEST(AnalyticTrajectory, DerivativesMatchFiniteDifferences) {
  expect_derivatives_consistent(*make_roundtrip_test_motion(), 1);
  expect_derivatives_consistent(*make_motion_with_pauses(30.0, 5.0, 7), 2);
}

TEST(AnalyticTrajectory, SingleRotationClosedForm) {
  // One rotation about z after a start attitude: q(t) = q0 exp(z theta(t)), omega = z dtheta.
  const Eigen::Quaterniond q0 = quat_exp(Eigen::Vector3d(0.3, -0.2, 0.5));
  AnalyticTrajectory traj(0.0, 4.0, q0, Eigen::Vector3d(1, 2, 3));
  traj.add_rotation(1.0, 3.0, Eigen::Vector3d(0, 0, 2), 1.2);
  const SmoothStep step{1.0, 3.0};
  for (double t : {0.5, 1.3, 2.0, 2.9, 3.5}) {
    const KinematicState s = traj.at(t);
    const auto v = step.at(t);
    const Eigen::Quaterniond expected = q0 * quat_exp(Eigen::Vector3d(0, 0, 1.2 * v.s));
    EXPECT_LT(rotation_angle_between(s.q_W_S, expected), 1e-15);  // same formula, rounding
    EXPECT_NEAR(s.omega_WS_S.z(), 1.2 * v.ds_dt, 1e-15);
    EXPECT_EQ(s.omega_WS_S.head<2>().norm(), 0.0);
    EXPECT_EQ(s.p_W, Eigen::Vector3d(1, 2, 3));
  }
}

TEST(AnalyticTrajectory, RoundtripMotionProperties) {
  const auto traj = make_roundtrip_test_motion();
  EXPECT_EQ(traj->begin_s(), 0.0);
  EXPECT_EQ(traj->end_s(), 60.0);
  const auto rests = traj->rest_intervals();
  ASSERT_GE(rests.size(), 2u);
  EXPECT_EQ(rests.front().first, 0.0);
  EXPECT_GE(rests.front().second, 2.0);
  EXPECT_EQ(rests.back().second, 60.0);
  EXPECT_GE(rests.back().second - rests.back().first, 2.0);
  // Back at the start pose: every rotation is undone about the same axis, every translation
  // reversed; only rounding of the products remains.
  const KinematicState end = traj->at(60.0);
  EXPECT_LT(rotation_angle_between(end.q_W_S, Eigen::Quaterniond::Identity()), 1e-14);
  EXPECT_LT(end.p_W.norm(), 1e-14);
  // Peaks as promised: up to 3 rad/s about each of the three axes, up to 2 m/s^2.
  const Peaks p = peaks(*traj);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(p.omega_abs[i], 2.9) << "axis " << i;
    EXPECT_LE(p.omega_abs[i], 3.0) << "axis " << i;
  }
  EXPECT_GT(p.accel, 1.9);
  EXPECT_LE(p.accel, 2.0);
  // Exactly at rest inside the rests.
  for (const auto& [b, e] : rests) {
    const KinematicState s = traj->at(0.5 * (b + e));
    EXPECT_EQ(s.v_W.norm() + s.a_W.norm() + s.omega_WS_S.norm(), 0.0);
  }
}

TEST(AnalyticTrajectory, MotionWithPausesHasAPauseInEveryWindow) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const double max_move_s = 5.0;
    const auto traj = make_motion_with_pauses(60.0, max_move_s, seed);
    EXPECT_EQ(traj->end_s(), 60.0);
    const auto rests = traj->rest_intervals();
    EXPECT_GE(rests.front().second, 2.0);
    EXPECT_GE(rests.back().second - rests.back().first, 1.0);
    EXPECT_GT(rests.size(), 8u);  // 60 s of moves of <= 4.5 s: many of them
    // Every window of max_move_s contains a whole rest of >= 0.5 s.
    for (double t0 = 0.0; t0 + max_move_s <= 60.0; t0 += 0.01) {
      bool found = false;
      for (const auto& [b, e] : rests) {
        if (std::min(e, t0 + max_move_s) - std::max(b, t0) >= 0.5 - 1e-9) found = true;
      }
      ASSERT_TRUE(found) << "seed " << seed << " window at " << t0;
    }
    const Peaks p = peaks(*traj);
    EXPECT_LE(p.omega, 3.0 + 1e-9);  // by construction: kPeakSlope * angle / window <= 3
    EXPECT_LE(p.accel, 2.0 + 1e-9);
    EXPECT_GT(p.omega, 1.0);  // it does move
    for (double t = 0; t <= 60.0; t += 0.1) {
      const Eigen::Vector3d pos = traj->at(t).p_W;
      EXPECT_LE(pos.head<2>().cwiseAbs().maxCoeff(), 0.5 + 1e-12);
      EXPECT_LE(std::abs(pos.z()), 0.3 + 1e-12);
    }
  }
  // Determinism: the same seed gives the same motion, another seed another one.
  const auto a = make_motion_with_pauses(20.0, 4.0, 11);
  const auto b = make_motion_with_pauses(20.0, 4.0, 11);
  const auto c = make_motion_with_pauses(20.0, 4.0, 12);
  EXPECT_EQ(a->at(7.3).p_W, b->at(7.3).p_W);
  EXPECT_EQ(a->at(7.3).q_W_S.coeffs(), b->at(7.3).q_W_S.coeffs());
  EXPECT_NE(a->at(7.3).p_W, c->at(7.3).p_W);
  EXPECT_THROW(make_motion_with_pauses(60.0, 1.0, 1), std::invalid_argument);
}

TEST(AnalyticTrajectory, YamlSegmentsEndPose) {
  const auto config = imscal::ConfigNode::load_string(R"(
kind: segments
start: {position_m: [1, 0, 0], rotation_vector_deg: [0, 0, 90]}
segments:
  - duration_s: 2
  - {duration_s: 1.5, rotation_axis_S: [1, 0, 0], rotation_angle_deg: 90}
  - {duration_s: 2, translation_W_m: [0, 0.5, -0.25]}
  - duration_s: 1
)",
                                                      "inline");
  const auto traj = load_motion(config);
  EXPECT_DOUBLE_EQ(traj->end_s(), 6.5);
  const KinematicState end = traj->at(6.5);
  // Rz(90 deg) then Rx(90 deg) about the body x axis: S x -> W y, S y -> W z, S z -> W x.
  Eigen::Matrix3d expected;
  expected << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  EXPECT_LT((end.q_W_S.toRotationMatrix() - expected).norm(), 1e-15);
  EXPECT_LT((end.p_W - Eigen::Vector3d(1, 0.5, -0.25)).norm(), 1e-15);
  const auto rests = traj->rest_intervals();
  ASSERT_EQ(rests.size(), 2u);
  EXPECT_EQ(rests[0], std::make_pair(0.0, 2.0));
  EXPECT_EQ(rests[1], std::make_pair(5.5, 6.5));
}

TEST(AnalyticTrajectory, YamlErrorsNameTheKey) {
  try {
    load_motion(imscal::ConfigNode::load_string(
        "kind: segments\nsegments:\n  - {duration_s: 1, rotation_axiz_S: [1, 0, 0]}\n", "m.yaml"));
    FAIL() << "unknown key accepted";
  } catch (const imscal::InputError& e) {
    EXPECT_EQ(e.field(), "segments[0].rotation_axiz_S");
    EXPECT_EQ(e.line(), 3u);
  }
  EXPECT_THROW(load_motion(imscal::ConfigNode::load_string("kind: spiral\n", "m.yaml")),
               imscal::InputError);
}

TEST(AnalyticTrajectory, ShippedMotionsLoad) {
  for (const char* name : {"roundtrip-test.yaml", "pauses-60s.yaml", "pick-and-place.yaml"}) {
    const auto traj =
        load_motion_file(std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets/motions" / name);
    EXPECT_GT(traj->end_s(), 10.0) << name;
    EXPECT_GE(traj->rest_intervals().front().second, 2.0) << name;  // room for alignment
  }
}
