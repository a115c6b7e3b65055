// SensorErrorModel: apply against the model written out by hand, correct as its exact inverse
// (round trip to 1e-12 relative), per-sample intervals for increments, YAML units and errors.
#include <gtest/gtest.h>

#include <random>
#include <utility>

#include "core/input_error.hpp"
#include "ims/sensor_error_model.hpp"

using namespace imscal::ims;

namespace {
// Errors of a poor unit (large values make a wrong formula visible): biases of ~1 deg/s and
// ~0.05 m/s^2, scale factors ~1e-3, misalignments ~1e-3 rad.
SensorErrorModel poor_unit(unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  SensorErrorModel m;
  for (TriadErrors* t : {&m.gyro, &m.acc}) {
    const double bias_scale = t == &m.gyro ? 0.02 : 0.05;
    for (int i = 0; i < 3; ++i) {
      t->bias[i] = bias_scale * n(rng);
      t->scale_factor[i] = 1e-3 * n(rng);
      for (int j = 0; j < 3; ++j) t->misalignment(i, j) = i == j ? 0.0 : 1e-3 * n(rng);
    }
  }
  return m;
}

ImuSeries random_series(ImuQuantity quantity, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  ImuSeries s;
  s.quantity = quantity;
  s.nominal_dt_s = 0.01;
  double t = 0.0;
  for (int k = 0; k < 200; ++k) {
    t += 0.01 * (1.0 + 0.2 * (k % 3));  // uneven intervals: 0.01, 0.012, 0.014 s
    const double scale = quantity == ImuQuantity::kIncrements ? 0.01 : 1.0;
    s.samples.push_back({t, Eigen::Vector3d(n(rng), n(rng), n(rng)) * scale,
                         Eigen::Vector3d(n(rng), n(rng), 9.8 + n(rng)) * scale});
  }
  return s;
}
}  // namespace

TEST(SensorErrorModel, ApplyMatchesModelWrittenOut) {
  TriadErrors t;
  t.bias = Eigen::Vector3d(0.1, -0.2, 0.3);
  t.scale_factor = Eigen::Vector3d(1e-3, 2e-3, -1e-3);
  t.misalignment(0, 1) = 5e-4;   // x picks up y
  t.misalignment(2, 0) = -7e-4;  // z picks up x
  const Eigen::Vector3d x(1.0, 2.0, 3.0);
  const Eigen::Vector3d raw = t.apply(x, 0.01);
  EXPECT_NEAR(raw.x(), (1 + 1e-3) * 1.0 + 5e-4 * 2.0 + 0.1 * 0.01, 1e-15);
  EXPECT_NEAR(raw.y(), (1 + 2e-3) * 2.0 - 0.2 * 0.01, 1e-15);
  EXPECT_NEAR(raw.z(), (1 - 1e-3) * 3.0 - 7e-4 * 1.0 + 0.3 * 0.01, 1e-15);
}

TEST(SensorErrorModel, CorrectInvertsApplyOnSeries) {
  for (ImuQuantity q : {ImuQuantity::kIncrements, ImuQuantity::kRates}) {
    const SensorErrorModel errors = poor_unit(3);
    const ImuSeries truth = random_series(q, 4);
    const ImuSeries raw = apply(truth, errors);
    const ImuSeries back = correct(raw, errors);
    ASSERT_EQ(back.samples.size(), truth.samples.size());
    for (std::size_t k = 0; k < truth.samples.size(); ++k) {
      const ImuSample& a = truth.samples[k];
      const ImuSample& b = back.samples[k];
      // A is within 1e-2 of I (condition ~1): the round trip loses a few ulp; 1e-12 relative.
      EXPECT_LT((a.gyro - b.gyro).norm(), 1e-12 * a.gyro.norm());
      EXPECT_LT((a.acc - b.acc).norm(), 1e-12 * a.acc.norm());
      EXPECT_EQ(a.t_s, b.t_s);
    }
    // Increments carry bias * (their own interval): sample 1 spans 0.012 s, sample 0 the nominal.
    if (q == ImuQuantity::kIncrements) {
      for (std::size_t k : {0u, 1u, 2u}) {
        const double dt = k == 0 ? 0.01 : truth.samples[k].t_s - truth.samples[k - 1].t_s;
        const Eigen::Vector3d expected =
            errors.gyro.sensitivity() * truth.samples[k].gyro + errors.gyro.bias * dt;
        EXPECT_LT((raw.samples[k].gyro - expected).norm(), 1e-16);  // same formula, ulp level
      }
      EXPECT_NEAR(sample_interval(truth, 1), 0.012, 1e-15);
    } else {
      const Eigen::Vector3d expected =
          errors.acc.sensitivity() * truth.samples[5].acc + errors.acc.bias;
      EXPECT_LT((raw.samples[5].acc - expected).norm(), 1e-14);
    }
  }
}

// In place (the overload for a series the caller gives up) gives the copy's values bit for bit,
// also over uneven intervals, where each sample's interval reads the previous, corrected one.
TEST(SensorErrorModel, CorrectInPlaceEqualsTheCopy) {
  for (ImuQuantity q : {ImuQuantity::kIncrements, ImuQuantity::kRates}) {
    const SensorErrorModel errors = poor_unit(5);
    const ImuSeries raw = apply(random_series(q, 6), errors);
    const ImuSeries copy = correct(raw, errors);
    ImuSeries given = raw;
    const ImuSeries in_place = correct(std::move(given), errors);
    ASSERT_EQ(in_place.samples.size(), copy.samples.size());
    EXPECT_EQ(in_place.quantity, copy.quantity);
    for (std::size_t k = 0; k < copy.samples.size(); ++k) {
      EXPECT_EQ(in_place.samples[k].t_s, copy.samples[k].t_s);
      EXPECT_EQ(in_place.samples[k].gyro, copy.samples[k].gyro);
      EXPECT_EQ(in_place.samples[k].acc, copy.samples[k].acc);
    }
  }
}

TEST(SensorErrorModel, YamlUnitsAndRoundTrip) {
  const auto config = imscal::ConfigNode::load_string(R"(
gyro:
  bias_deg_per_h: [1, -2, 3]
  scale_factor_ppm: [10, 0, -5]
  misalignment_arcsec: [[0, 1, 0], [0, 0, 0], [0, -2, 0]]
accelerometer:
  bias_ug: [100, 0, -50]
)",
                                                      "errors.yaml");
  const SensorErrorModel m = parse_sensor_error_model(config);
  // 1 deg/h = pi / 180 / 3600 rad/s = 4.84813681109536e-6 rad/s; 1 arcsec the same in rad.
  EXPECT_NEAR(m.gyro.bias.x(), 4.84813681109536e-6, 1e-20);
  EXPECT_NEAR(m.gyro.bias.y(), -2 * 4.84813681109536e-6, 1e-20);
  EXPECT_NEAR(m.gyro.scale_factor.x(), 1e-5, 1e-20);
  EXPECT_NEAR(m.gyro.misalignment(0, 1), 4.84813681109536e-6, 1e-20);
  EXPECT_NEAR(m.gyro.misalignment(2, 1), -2 * 4.84813681109536e-6, 1e-20);
  // 1 ug = 9.80665e-6 m/s^2 (standard gravity).
  EXPECT_NEAR(m.acc.bias.x(), 100 * 9.80665e-6, 1e-18);
  EXPECT_EQ(m.acc.scale_factor, Eigen::Vector3d::Zero());  // absent keys: zero

  const SensorErrorModel poor = poor_unit(9);
  const SensorErrorModel back =
      parse_sensor_error_model(imscal::ConfigNode::load_string(to_yaml(poor), "round trip"));
  // 17 digits in the file; only the unit conversions round: a few ulp.
  for (auto [a, b] : {std::pair{&poor.gyro, &back.gyro}, std::pair{&poor.acc, &back.acc}}) {
    EXPECT_LT((a->bias - b->bias).norm(), 1e-15 * a->bias.norm());
    EXPECT_LT((a->scale_factor - b->scale_factor).norm(), 1e-15 * a->scale_factor.norm());
    EXPECT_LT((a->misalignment - b->misalignment).norm(), 1e-15 * a->misalignment.norm());
  }
}

TEST(SensorErrorModel, YamlErrorsNameFieldAndLine) {
  try {
    parse_sensor_error_model(
        imscal::ConfigNode::load_string("gyro:\n  bias_deg_per_hour: [1, 2, 3]\n", "e.yaml"));
    FAIL() << "unknown key accepted";
  } catch (const imscal::InputError& e) {
    EXPECT_EQ(e.field(), "gyro.bias_deg_per_hour");
    EXPECT_EQ(e.line(), 2u);
  }
  try {
    parse_sensor_error_model(imscal::ConfigNode::load_string(
        "gyro:\n  misalignment_arcsec:\n    - [0, 1, 2]\n    - [3, 4, 5]\n    - [6, 7, 0]\n",
        "e.yaml"));
    FAIL() << "non-zero diagonal accepted";
  } catch (const imscal::InputError& e) {
    EXPECT_EQ(e.field(), "gyro.misalignment_arcsec[1]");
    EXPECT_EQ(e.line(), 4u);
  }
  EXPECT_THROW(parse_sensor_error_model(
                   imscal::ConfigNode::load_string("accelerometer:\n  bias_ug: [1, 2]\n", "e")),
               imscal::InputError);
}
