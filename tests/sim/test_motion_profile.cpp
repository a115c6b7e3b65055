// 1-D motion profiles: exact distance, rest at both ends, limits respected, continuity (checked
// as Lipschitz bounds on a dense grid: |x(t+dt) - x(t)| <= bound * dt), derivatives consistent
// with central differences, and durations against the textbook closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "sim/motion_profile.hpp"

namespace imscal::sim {
namespace {

struct Case {
  const char* name;
  ProfileKind kind;
  double distance;
  ProfileLimits limits;
};

// Closed-form duration for rest-to-rest motion (independent of the piece construction):
// trapezoid T = D/V + V/A (cruise) or 2 sqrt(D/A) (triangle); S-curve with a and v reached
// T = D/V + V/A + A/J.
double trapezoid_duration(double d, const ProfileLimits& l) {
  d = std::abs(d);
  if (l.velocity * l.velocity / l.acceleration <= d) {
    return d / l.velocity + l.velocity / l.acceleration;
  }
  return 2.0 * std::sqrt(d / l.acceleration);
}

const Case kCases[] = {
    {"trapezoid full", ProfileKind::kTrapezoidal, 2.0, {1.0, 2.0, 0.0}},
    {"trapezoid triangle", ProfileKind::kTrapezoidal, 0.2, {1.0, 2.0, 0.0}},
    {"trapezoid backwards", ProfileKind::kTrapezoidal, -1.5, {0.7, 3.0, 0.0}},
    {"scurve full", ProfileKind::kJerkLimited, 2.0, {1.0, 2.0, 20.0}},
    {"scurve a not reached (v j < a^2)", ProfileKind::kJerkLimited, 2.0, {1.0, 4.0, 5.0}},
    {"scurve v not reached, a reached", ProfileKind::kJerkLimited, 0.5, {1.0, 2.0, 40.0}},
    {"scurve neither reached", ProfileKind::kJerkLimited, 0.01, {1.0, 2.0, 20.0}},
    {"scurve backwards", ProfileKind::kJerkLimited, -0.8, {0.4, 2.0, 20.0}},
    {"scurve tiny", ProfileKind::kJerkLimited, 1e-7, {2.7, 3.5, 35.0}},
};

class ProfileCases : public ::testing::TestWithParam<Case> {};

TEST_P(ProfileCases, EndsExactlyAtRestWithinLimitsAndContinuous) {
  const Case& c = GetParam();
  const MotionProfile p = MotionProfile::plan(c.kind, c.distance, c.limits);
  const double T = p.duration();
  ASSERT_GT(T, 0.0);
  // Distance: the last piece ends at D up to rounding of ~10 polynomial terms (1e-15 relative);
  // past the end the profile returns D exactly.
  const ProfileState end_inside = p.at(T * (1.0 - 1e-15));
  EXPECT_NEAR(end_inside.position, c.distance, 1e-12 * std::max(1.0, std::abs(c.distance)));
  EXPECT_EQ(p.at(T).position, c.distance);
  EXPECT_EQ(p.at(T + 1.0).velocity, 0.0);
  EXPECT_EQ(p.at(0.0).position, 0.0);
  EXPECT_EQ(p.at(0.0).velocity, 0.0);
  // Velocity is ~0 at the very end from inside (rest to rest); bound: a_max * 1e-15 T.
  EXPECT_NEAR(end_inside.velocity, 0.0, 1e-12);

  // Dense grid, 20001 points, not aligned with the piece borders.
  const int n = 20000;
  const double dt = T / n;
  // Slack on the Lipschitz bounds and limits: rounding of the polynomials (1e-12 relative).
  const double slack = 1e-9;
  ProfileState prev = p.at(0.0);
  double peak_v = 0.0, peak_a = 0.0;
  for (int k = 1; k <= n; ++k) {
    const double t = k * dt;
    const ProfileState s = p.at(t);
    EXPECT_LE(std::abs(s.velocity), c.limits.velocity * (1 + slack)) << c.name << " t=" << t;
    EXPECT_LE(std::abs(s.acceleration), c.limits.acceleration * (1 + slack)) << c.name;
    // Position continuous with |v| <= v_max; velocity continuous with |a| <= a_max.
    EXPECT_LE(std::abs(s.position - prev.position), c.limits.velocity * dt * (1 + slack) + 1e-15);
    EXPECT_LE(std::abs(s.velocity - prev.velocity),
              c.limits.acceleration * dt * (1 + slack) + 1e-15);
    if (c.kind == ProfileKind::kJerkLimited) {
      // Acceleration continuous with |jerk| <= j_max.
      EXPECT_LE(std::abs(s.acceleration - prev.acceleration),
                c.limits.jerk * dt * (1 + slack) + 1e-12)
          << c.name << " t=" << t;
    }
    // Monotone: never moves against the direction of travel.
    EXPECT_GE(s.velocity * std::copysign(1.0, c.distance), -1e-12);
    peak_v = std::max(peak_v, std::abs(s.velocity));
    peak_a = std::max(peak_a, std::abs(s.acceleration));
    prev = s;
  }
  // The reported peaks are the sampled ones (the grid step changes v by < a dt and a by < j dt).
  EXPECT_NEAR(p.peak_velocity(), peak_v, c.limits.acceleration * dt);
  if (c.kind == ProfileKind::kJerkLimited) {
    EXPECT_NEAR(p.peak_acceleration(), peak_a, c.limits.jerk * dt);
  }

  // Central differences: |(s(t+h) - s(t-h)) / 2h - v(t)| <= a_max h / 2 (holds across acceleration
  // jumps too), and for the S-curve |(v(t+h) - v(t-h)) / 2h - a(t)| <= j_max h / 2. Plus
  // rounding: 1e-15 |D| / h.
  const double h = T * 1e-5;
  for (int k = 1; k < 1000; ++k) {
    const double t = T * k / 1000.0 + 0.37 * h;
    const ProfileState s = p.at(t);
    const double dv = (p.at(t + h).position - p.at(t - h).position) / (2 * h);
    EXPECT_NEAR(dv, s.velocity, c.limits.acceleration * h / 2 + 1e-14 * std::abs(c.distance) / h);
    if (c.kind == ProfileKind::kJerkLimited) {
      const double da = (p.at(t + h).velocity - p.at(t - h).velocity) / (2 * h);
      EXPECT_NEAR(da, s.acceleration, c.limits.jerk * h / 2 + 1e-14 * c.limits.velocity / h);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(All, ProfileCases, ::testing::ValuesIn(kCases));

TEST(MotionProfile, TrapezoidDurationMatchesClosedForm) {
  for (const Case& c : kCases) {
    if (c.kind != ProfileKind::kTrapezoidal) continue;
    const MotionProfile p = MotionProfile::plan(c.kind, c.distance, c.limits);
    // Closed form vs. sum of pieces: rounding only.
    EXPECT_NEAR(p.duration(), trapezoid_duration(c.distance, c.limits), 1e-12) << c.name;
  }
}

TEST(MotionProfile, SCurveDurationAndPeaksMatchClosedForms) {
  // v and a reached: T = D/V + V/A + A/J, peak v = V, peak a = A.
  const ProfileLimits l{1.0, 2.0, 20.0};
  const MotionProfile full = MotionProfile::plan(ProfileKind::kJerkLimited, 2.0, l);
  EXPECT_NEAR(full.duration(), 2.0 / 1.0 + 1.0 / 2.0 + 2.0 / 20.0, 1e-12);
  EXPECT_NEAR(full.peak_velocity(), 1.0, 1e-12);
  EXPECT_NEAR(full.peak_acceleration(), 2.0, 1e-12);
  // Neither reached (D = 0.01): pure jerk phases of length tj, D = 2 j tj^3 -> T = 4 tj.
  const MotionProfile tiny = MotionProfile::plan(ProfileKind::kJerkLimited, 0.01, l);
  const double tj = std::cbrt(0.01 / (2 * 20.0));
  EXPECT_NEAR(tiny.duration(), 4 * tj, 1e-12);
  EXPECT_NEAR(tiny.peak_acceleration(), 20.0 * tj, 1e-12);
  EXPECT_LT(tiny.peak_acceleration(), 2.0);
  // a not reached but v reached (V J < A^2): ramp 2 sqrt(V/J), T = D/V + 2 sqrt(V/J).
  const ProfileLimits soft{1.0, 4.0, 5.0};
  const MotionProfile p = MotionProfile::plan(ProfileKind::kJerkLimited, 2.0, soft);
  EXPECT_NEAR(p.duration(), 2.0 / 1.0 + 2.0 * std::sqrt(1.0 / 5.0), 1e-12);
  EXPECT_NEAR(p.peak_acceleration(), std::sqrt(1.0 * 5.0), 1e-12);
}

TEST(MotionProfile, StretchScalesRatesAndKeepsDistance) {
  const MotionProfile p = MotionProfile::plan(ProfileKind::kJerkLimited, 0.8, {0.4, 2.0, 20.0});
  const double k = 1.25;
  const MotionProfile q = p.stretched_to(k * p.duration());
  EXPECT_NEAR(q.duration(), k * p.duration(), 1e-15);
  EXPECT_EQ(q.at(q.duration()).position, 0.8);
  for (double f : {0.1, 0.33, 0.5, 0.9}) {
    const ProfileState a = p.at(f * p.duration());
    const ProfileState b = q.at(f * q.duration());
    // s_k(k t) = s(t), v_k = v / k, a_k = a / k^2: rounding only.
    EXPECT_NEAR(b.position, a.position, 1e-15);
    EXPECT_NEAR(b.velocity, a.velocity / k, 1e-14);
    EXPECT_NEAR(b.acceleration, a.acceleration / (k * k), 1e-13);
  }
  EXPECT_NEAR(q.peak_velocity(), 0.4 / k, 1e-14);
  EXPECT_THROW(p.stretched_to(0.5 * p.duration()), std::invalid_argument);
}

TEST(MotionProfile, ZeroDistanceAndBadLimits) {
  const MotionProfile p = MotionProfile::plan(ProfileKind::kJerkLimited, 0.0, {1, 1, 1});
  EXPECT_EQ(p.duration(), 0.0);
  EXPECT_EQ(p.at(0.5).position, 0.0);
  EXPECT_THROW(MotionProfile::plan(ProfileKind::kTrapezoidal, 1.0, {0.0, 1.0, 0.0}),
               std::invalid_argument);
  EXPECT_THROW(MotionProfile::plan(ProfileKind::kJerkLimited, 1.0, {1.0, 1.0, 0.0}),
               std::invalid_argument);
  EXPECT_THROW(MotionProfile::plan(ProfileKind::kTrapezoidal, 1.0, {1.0, -2.0, 0.0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace imscal::sim
