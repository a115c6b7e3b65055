// The least-squares kernels (ident/lagged_products.hpp) against their definitions summed in long
// double, at every tail length and lag count, and the SSE2 and AVX builds against each other
// (bitwise: the claim that a fit gives the same bits on every x86-64 machine).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "ident/lagged_products.hpp"

namespace imscal::ident {
namespace {

struct Signals {
  std::vector<double> a, b;  // b holds `history` samples before the first row
  std::size_t history = 0;
};

Signals random_signals(std::size_t len, std::size_t history, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Signals s{std::vector<double>(len), std::vector<double>(len + history), history};
  for (auto& v : s.a) v = normal(rng);
  for (auto& v : s.b) v = 3.0 + normal(rng);  // an offset: sums with cancellation-free size
  return s;
}

// Lengths around the kernels' blocks (8 rows of the dots, 16 of the FIR) and lag counts around
// their blocks of 4 lags.
const std::vector<std::size_t> kLengths{1, 7, 8, 9, 15, 16, 17, 31, 33, 100, 2048};
const std::vector<int> kCounts{1, 2, 3, 4, 5, 7, 8, 9, 33, 64};

TEST(LaggedProducts, DotsEqualTheirDefinition) {
  std::mt19937_64 rng(1);
  for (std::size_t len : kLengths) {
    for (int count : kCounts) {
      const Signals s = random_signals(len, std::size_t(count), rng);
      const double* b = s.b.data() + s.history;
      std::vector<double> out(std::size_t(count), 0.5);  // the kernel adds to what is there
      add_lagged_dots(s.a.data(), b, len, count, out.data());
      for (int j = 0; j < count; ++j) {
        long double truth = 0.5L, magnitude = 0.5L;
        for (std::size_t i = 0; i < len; ++i) {
          truth += static_cast<long double>(s.a[i]) * b[std::ptrdiff_t(i) - j];
          magnitude += std::fabs(static_cast<long double>(s.a[i]) * b[std::ptrdiff_t(i) - j]);
        }
        // Rounding of a sum of len products in double: <= len × 1.1e-16 of the sum of their
        // magnitudes (Higham's bound for any summation order); 4 × that.
        EXPECT_NEAR(out[std::size_t(j)], double(truth),
                    4.0 * double(len) * 1.1e-16 * double(magnitude))
            << "len " << len << " count " << count << " lag " << j;
      }
    }
  }
}

TEST(LaggedProducts, FirEqualsItsDefinition) {
  std::mt19937_64 rng(2);
  for (std::size_t len : kLengths) {
    for (int count : kCounts) {
      const Signals s = random_signals(len, std::size_t(count), rng);
      const double* x = s.b.data() + s.history;
      std::vector<double> w(static_cast<std::size_t>(count));
      std::normal_distribution<double> normal(0.0, 1.0);
      for (auto& v : w) v = normal(rng);
      std::vector<double> out = s.a;  // the kernel subtracts from what is there
      subtract_fir(x, w.data(), count, len, out.data());
      for (std::size_t i = 0; i < len; ++i) {
        long double truth = s.a[i], magnitude = std::fabs(s.a[i]);
        for (int j = 0; j < count; ++j) {
          truth -= static_cast<long double>(w[std::size_t(j)]) * x[std::ptrdiff_t(i) - j];
          magnitude +=
              std::fabs(static_cast<long double>(w[std::size_t(j)]) * x[std::ptrdiff_t(i) - j]);
        }
        EXPECT_NEAR(out[i], double(truth), 4.0 * double(count + 1) * 1.1e-16 * double(magnitude))
            << "len " << len << " count " << count << " row " << i;
      }
    }
  }
}

TEST(LaggedProducts, Sse2AndAvxBuildsAgreeBitwise) {
  if (!detail::cpu_has_avx()) GTEST_SKIP() << "this CPU has no AVX: only the SSE2 build runs";
  std::mt19937_64 rng(3);
  for (std::size_t len : kLengths) {
    for (int count : kCounts) {
      const Signals s = random_signals(len, std::size_t(count), rng);
      const double* b = s.b.data() + s.history;
      std::vector<double> sse2(std::size_t(count), 0.0), avx = sse2;
      detail::add_lagged_dots_sse2(s.a.data(), b, len, count, sse2.data());
      detail::add_lagged_dots_avx(s.a.data(), b, len, count, avx.data());
      EXPECT_EQ(std::memcmp(sse2.data(), avx.data(), sse2.size() * sizeof(double)), 0)
          << "dots, len " << len << " count " << count;
      std::vector<double> fir_sse2 = s.a, fir_avx = s.a;
      detail::subtract_fir_sse2(b, s.a.data(), std::min<int>(count, int(len)), len,
                                fir_sse2.data());
      detail::subtract_fir_avx(b, s.a.data(), std::min<int>(count, int(len)), len, fir_avx.data());
      EXPECT_EQ(std::memcmp(fir_sse2.data(), fir_avx.data(), len * sizeof(double)), 0)
          << "FIR, len " << len << " count " << count;
    }
  }
}

}  // namespace
}  // namespace imscal::ident
