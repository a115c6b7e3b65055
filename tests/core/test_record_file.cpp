// RecordFile: records written in order come back bit for bit, in any order of reading, across
// block boundaries, and with a last block shorter than the others.
#include "core/record_file.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

namespace {

// Record r holds values whose bits must survive: fractions, a denormal, -0, infinity, NaN.
std::vector<double> record_values(std::size_t r) {
  return {double(r) / 3.0,
          std::ldexp(1.0, -1070) * double(r + 1),
          -0.0,
          std::numeric_limits<double>::infinity(),
          std::nan(""),
          1e300 * double(r)};
}

bool same_bits(const double* a, const std::vector<double>& b) {
  return std::memcmp(a, b.data(), b.size() * sizeof(double)) == 0;
}

TEST(RecordFile, RecordsComeBackBitForBitInReverseAndRandomOrder) {
  // 4 records per block and 23 records: 5 full blocks and one of 3.
  imscal::RecordFile file(6, 4, "test records");
  for (std::size_t r = 0; r < 23; ++r) file.append(record_values(r).data());
  ASSERT_EQ(file.size(), 23u);
  for (std::size_t r = 23; r-- > 0;) EXPECT_TRUE(same_bits(file.record(r), record_values(r))) << r;
  for (std::size_t r : {0u, 22u, 5u, 4u, 3u, 19u, 20u, 0u})
    EXPECT_TRUE(same_bits(file.record(r), record_values(r))) << r;
}

TEST(RecordFile, ReadsFromTheBlockStillInMemory) {
  // Fewer records than a block: nothing reached the file before the first read.
  imscal::RecordFile file(6, 100, "test records");
  for (std::size_t r = 0; r < 3; ++r) file.append(record_values(r).data());
  for (std::size_t r = 0; r < 3; ++r) EXPECT_TRUE(same_bits(file.record(r), record_values(r)));
}

TEST(RecordFile, RefusesAnIndexPastTheEndAndAnAppendAfterReading) {
  imscal::RecordFile file(6, 2, "test records");
  file.append(record_values(0).data());
  EXPECT_THROW(file.record(1), std::out_of_range);
  file.record(0);
  EXPECT_THROW(file.append(record_values(1).data()), std::logic_error);
}

}  // namespace
