// Format dispatch of ims/imu_file (by extension, then by content; PSINS logs through
// ims/psins_reader), writes that refuse unknown kinds without touching the disk, and the
// rates <-> increments conversion of ims/imu_conversion against closed-form integrals.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "core/input_error.hpp"
#include "ims/imu_binary.hpp"
#include "ims/imu_conversion.hpp"
#include "ims/imu_csv.hpp"
#include "ims/imu_file.hpp"
#include "ims/psins_reader.hpp"
#include "tests/support/scratch_dir.hpp"

namespace fs = std::filesystem;
using imscal::InputError;
using imscal::Overwrite;
using imscal::ims::ImuFileKind;
using imscal::ims::ImuQuantity;
using imscal::ims::ImuReadOptions;
using imscal::ims::ImuReadReport;
using imscal::ims::ImuSample;
using imscal::ims::ImuSeries;

namespace {

class ImuFile : public imscal::test_support::ScratchDirTest {};

// 1.5 s at rest (gravity on z), with a slow turn about z.
ImuSeries rest_series(ImuQuantity quantity) {
  ImuSeries s;
  s.quantity = quantity;
  s.nominal_dt_s = 0.01;
  for (int i = 0; i < 150; ++i) {
    const double t = 0.01 * (i + 1);
    const double scale = quantity == ImuQuantity::kIncrements ? 0.01 : 1.0;
    s.samples.push_back(ImuSample{t, Eigen::Vector3d(0, 0, 1e-3 * std::sin(i)) * scale,
                                  Eigen::Vector3d(0.01, 2e-4 * std::cos(i), 9.81) * scale});
  }
  return s;
}

bool same_samples(const ImuSeries& a, const ImuSeries& b) {
  if (a.samples.size() != b.samples.size() || a.quantity != b.quantity) return false;
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    if (a.samples[i].t_s != b.samples[i].t_s || a.samples[i].gyro != b.samples[i].gyro ||
        a.samples[i].acc != b.samples[i].acc) {
      return false;
    }
  }
  return true;
}

TEST_F(ImuFile, DispatchesOnExtensionThenOnContent) {
  const ImuSeries s = rest_series(ImuQuantity::kRates);
  imscal::ims::write_imu_file(dir_ / "a.csv", s, Overwrite::kAllow);
  imscal::ims::write_imu_file(dir_ / "a.IMSB", s, Overwrite::kAllow);  // case-insensitive
  EXPECT_EQ(imscal::ims::imu_file_kind(dir_ / "a.csv"), ImuFileKind::kCsv);
  EXPECT_EQ(imscal::ims::imu_file_kind(dir_ / "a.IMSB"), ImuFileKind::kBinary);
  EXPECT_EQ(imscal::ims::imu_file_kind(dir_ / "x.imu"), ImuFileKind::kPsins);
  // The writers chose the format: the text starts with the CSV header, the binary with magic.
  std::ifstream csv(dir_ / "a.csv");
  std::string first;
  std::getline(csv, first);
  EXPECT_EQ(first, "# imscal-imu: 1");
  EXPECT_TRUE(same_samples(imscal::ims::read_imu_binary(dir_ / "a.IMSB"), s));
  // Other extensions: by content.
  fs::copy_file(dir_ / "a.csv", dir_ / "csv.dat");
  fs::copy_file(dir_ / "a.IMSB", dir_ / "bin.dat");
  EXPECT_EQ(imscal::ims::imu_file_kind(dir_ / "csv.dat"), ImuFileKind::kCsv);
  EXPECT_EQ(imscal::ims::imu_file_kind(dir_ / "bin.dat"), ImuFileKind::kBinary);
  ImuReadReport report;
  EXPECT_TRUE(same_samples(imscal::ims::read_imu_file(dir_ / "csv.dat", {}, &report), s));
  EXPECT_EQ(report.samples, s.samples.size());
  EXPECT_TRUE(same_samples(imscal::ims::read_imu_file(dir_ / "bin.dat"), s));
  std::ofstream(dir_ / "other.dat") << "time,gx\n";
  try {
    imscal::ims::read_imu_file(dir_ / "other.dat");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("other.dat"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("unknown IMU file kind"), std::string::npos);
  }
}

TEST_F(ImuFile, WritesOnlyKnownKindsAndNothingElse) {
  const ImuSeries s = rest_series(ImuQuantity::kRates);
  EXPECT_THROW(imscal::ims::write_imu_file(dir_ / "x.imu", s, Overwrite::kAllow),
               std::invalid_argument);
  EXPECT_THROW(imscal::ims::write_imu_file(dir_ / "x.txt", s, Overwrite::kAllow),
               std::invalid_argument);
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(ImuFile, ReadsPsinsLogsLikeThePsinsReader) {
  // 1 s at rest at 100 Hz: acc z counts of 1 ug*s each give dv = count * 1e-6 * g; at rest
  // dv = g * dt, so count = dt / 1e-6 = 10000.
  const fs::path file = dir_ / "static.imu";
  {
    std::ofstream out(file);
    out << "% PSINS test log\n0 0 0 0 0 0\n48.78 9.18 245 0 10 9.80665\n1 1 1 1 1 1\n";
    for (int i = 0; i < 100; ++i) out << "0 0 " << (i % 2) << " 3 -2 10000\n";
  }
  ImuReadReport report;
  const ImuSeries via_dispatch = imscal::ims::read_imu_file(file, ImuReadOptions{}, &report);
  const ImuSeries direct = imscal::ims::read_psins(file);
  EXPECT_TRUE(same_samples(via_dispatch, direct));
  EXPECT_EQ(report.samples, 100u);
  // The dispatch validates: the static |f| is the file's g = 9.80665 plus 6.3e-7 m/s^2 from the
  // horizontal components (2.9e-3 and 2.0e-3 m/s^2), compared with gravity at the file's site.
  ASSERT_TRUE(report.static_specific_force_m_s2.has_value());
  EXPECT_NEAR(*report.static_specific_force_m_s2, 9.80665 + 6.3e-7, 1e-8);
}

// ---------------------------------------------------------------------------------------------
// rates <-> increments.

TEST(ImuConversion, RectangleRuleAgainstTheExactIntegralOfALinearRate) {
  // omega(t) = a + b t: the exact increment over (t - dt, t] is a dt + b (t dt - dt^2 / 2);
  // the rectangle rule with the end value gives (a + b t) dt, larger by b dt^2 / 2 exactly.
  const double a = 0.3, b = 2.0, dt = 0.002;
  ImuSeries rates;
  rates.quantity = ImuQuantity::kRates;
  rates.nominal_dt_s = dt;
  for (int i = 0; i < 500; ++i) {
    const double t = dt * (i + 1);
    rates.samples.push_back(
        ImuSample{t, Eigen::Vector3d(a + b * t, 0, -(a + b * t)), Eigen::Vector3d(0, 9.8, b * t)});
  }
  const ImuSeries increments = imscal::ims::rates_to_increments(rates);
  EXPECT_EQ(increments.quantity, ImuQuantity::kIncrements);
  // In place: the same values bit for bit.
  ImuSeries given = rates;
  const ImuSeries in_place = imscal::ims::rates_to_increments(std::move(given));
  EXPECT_EQ(in_place.quantity, ImuQuantity::kIncrements);
  ASSERT_EQ(in_place.samples.size(), increments.samples.size());
  for (std::size_t i = 0; i < increments.samples.size(); ++i) {
    EXPECT_EQ(in_place.samples[i].t_s, increments.samples[i].t_s);
    EXPECT_EQ(in_place.samples[i].gyro, increments.samples[i].gyro);
    EXPECT_EQ(in_place.samples[i].acc, increments.samples[i].acc);
  }
  for (std::size_t i = 0; i < increments.samples.size(); ++i) {
    const double t = rates.samples[i].t_s;
    const double step = i == 0 ? dt : t - rates.samples[i - 1].t_s;
    const double exact = a * step + b * (t * step - step * step / 2.0);
    // Rounding of t and of the products: ~1e-16 relative on values of ~1e-3.
    EXPECT_NEAR(increments.samples[i].gyro.x() - exact, b * step * step / 2.0, 1e-15) << i;
    EXPECT_NEAR(increments.samples[i].acc.y(), 9.8 * step, 1e-15) << i;
  }
  // Back to rates: the exact inverse up to rounding (a few ulp of values of order 1).
  const ImuSeries back = imscal::ims::increments_to_rates(increments);
  for (std::size_t i = 0; i < back.samples.size(); ++i) {
    EXPECT_NEAR(back.samples[i].gyro.z(), rates.samples[i].gyro.z(), 4e-15) << i;
    EXPECT_NEAR(back.samples[i].acc.z(), rates.samples[i].acc.z(), 4e-15) << i;
    EXPECT_EQ(back.samples[i].t_s, rates.samples[i].t_s);
  }
}

TEST(ImuConversion, IncrementsOfASineGiveItsMeanRate) {
  // Increments that are the exact integral of omega = sin(w t) give, divided by dt, the mean
  // rate (cos(w (t-dt)) - cos(w t)) / (w dt) = sin(w (t - dt/2)) * sinc: equal to the rate at
  // the interval's middle to O((w dt)^2).
  const double w = 5.0, dt = 0.01;
  ImuSeries increments;
  increments.quantity = ImuQuantity::kIncrements;
  increments.nominal_dt_s = dt;
  for (int i = 0; i < 300; ++i) {
    const double t = dt * (i + 1);
    const double integral = (std::cos(w * (t - dt)) - std::cos(w * t)) / w;
    increments.samples.push_back(
        ImuSample{t, Eigen::Vector3d(integral, 0, 0), Eigen::Vector3d::Zero()});
  }
  const ImuSeries rates = imscal::ims::to_quantity(increments, ImuQuantity::kRates);
  const double sinc = std::sin(w * dt / 2) / (w * dt / 2);
  for (std::size_t i = 0; i < rates.samples.size(); ++i) {
    const double t_mid = rates.samples[i].t_s - dt / 2;
    // Closed form of the mean rate; cancellation in the cos difference costs ~1e-16 / 5e-2.
    EXPECT_NEAR(rates.samples[i].gyro.x(), sinc * std::sin(w * t_mid), 1e-12) << i;
    // Against the midpoint rate: (w dt)^2 / 24 = 1e-4 relative.
    EXPECT_NEAR(rates.samples[i].gyro.x(), std::sin(w * t_mid), 1.1e-4) << i;
  }
}

TEST(ImuConversion, RefusesTheWrongQuantityAndNonIncreasingTime) {
  ImuSeries s = rest_series(ImuQuantity::kRates);
  EXPECT_THROW(imscal::ims::increments_to_rates(s), std::invalid_argument);
  EXPECT_TRUE(same_samples(imscal::ims::to_quantity(s, ImuQuantity::kRates), s));
  s.samples[10].t_s = s.samples[9].t_s;
  EXPECT_THROW(imscal::ims::rates_to_increments(s), std::invalid_argument);
}

}  // namespace
