// The smoother's per-instant files (ims/zupt_smoother_records.hpp): every value comes back bit
// for bit, across the files' blocks (1024 instants), with the smoothed errors written from the
// last instant to the first and read by instant, and the instants read in any order.
#include "ims/zupt_smoother_records.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

namespace imscal::ims::zupt_records {
namespace {

constexpr std::size_t kInstants = 2500;  // more than two blocks

ErrorVector random_vector(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  ErrorVector v;
  for (int i = 0; i < v.size(); ++i) v[i] = n(rng) * std::pow(10.0, double(i % 7) - 3.0);
  return v;
}

TEST(ZuptSmootherRecords, InstantsComeBackBitForBit) {
  std::mt19937_64 rng(11);
  std::vector<Epoch> written(kInstants);
  EpochFile file;
  for (std::size_t k = 0; k < kInstants; ++k) {
    Epoch& e = written[k];
    e.last_sample = k * 20 + (k == kInstants - 1 ? (std::size_t{1} << 40) : 0);  // a large index
    e.t_s = 1234.5 + 0.01 * double(k);
    e.correction = random_vector(rng);
    e.gyro_bias = random_vector(rng).head<3>();
    e.acc_bias = random_vector(rng).tail<3>();
    file.append(e);
  }
  ASSERT_EQ(file.size(), kInstants);
  // Backwards (as the backward pass reads them), then forwards.
  for (std::size_t k = kInstants; k-- > 0;)
    EXPECT_EQ(file.read(k).correction, written[k].correction);
  for (std::size_t k = 0; k < kInstants; ++k) {
    const Epoch e = file.read(k);
    EXPECT_EQ(e.last_sample, written[k].last_sample);
    EXPECT_EQ(e.t_s, written[k].t_s);
    EXPECT_EQ(e.correction, written[k].correction);
    EXPECT_EQ(e.gyro_bias, written[k].gyro_bias);
    EXPECT_EQ(e.acc_bias, written[k].acc_bias);
  }
}

TEST(ZuptSmootherRecords, SmoothedErrorsWrittenBackwardsReadByInstant) {
  std::mt19937_64 rng(12);
  std::vector<SmoothedError> by_instant(kInstants);
  for (SmoothedError& s : by_instant) {
    s.after = random_vector(rng);
    s.before = random_vector(rng);
    s.variance = random_vector(rng).cwiseAbs();
  }
  SmoothedErrorFile file;
  for (std::size_t k = kInstants; k-- > 0;) file.append_before(by_instant[k]);
  ASSERT_EQ(file.size(), kInstants);
  // Instants k - 1 and k together, as the state stream reads them.
  for (std::size_t k = 1; k < kInstants; ++k) {
    for (const std::size_t i : {k - 1, k}) {
      const SmoothedError s = file.read(i);
      EXPECT_EQ(s.after, by_instant[i].after);
      EXPECT_EQ(s.before, by_instant[i].before);
      EXPECT_EQ(s.variance, by_instant[i].variance);
    }
  }
}

}  // namespace
}  // namespace imscal::ims::zupt_records
