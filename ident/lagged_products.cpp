#include "ident/lagged_products.hpp"

#include <cstddef>

// The 32-byte vectors below never cross a call boundary (the helpers that take or return them
// are always inlined), so the compilers' warning that their ABI differs without AVX does not
// apply (GCC and clang both know -Wpsabi).
#pragma GCC diagnostic ignored "-Wpsabi"

namespace imscal::ident {
namespace {

// Four doubles, one AVX register (two SSE2 registers in the SSE2 build): explicit vectors, so
// that the lane of every term is fixed by the code and not by the compiler's vectoriser.
using V4 = double __attribute__((vector_size(32)));

[[gnu::always_inline]] inline V4 load(const double* p) {
  V4 v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::always_inline]] inline void store(double* p, const V4& v) {
  __builtin_memcpy(p, &v, sizeof v);
}

// The fixed reduction tree of 8 lane sums (the same as arx_fit.cpp's lane_dot).
[[gnu::always_inline]] inline double reduce_lanes(const V4& low, const V4& high) {
  return ((low[0] + high[0]) + (low[2] + high[2])) + ((low[1] + high[1]) + (low[3] + high[3]));
}

// K lags at once: entry i of every sum goes to lane i mod 8 (the tail after the last full 8 to
// the first lanes), whichever K, so an output's rounding does not depend on the blocking.
template <int K>
[[gnu::always_inline]] inline void lagged_dots_block(const double* a, const double* b,
                                                     std::ptrdiff_t len, double* out) {
  V4 low[K], high[K];
  for (int k = 0; k < K; ++k) low[k] = high[k] = V4{0.0, 0.0, 0.0, 0.0};
  std::ptrdiff_t i = 0;
  for (; i + 8 <= len; i += 8) {
    const V4 a_low = load(a + i), a_high = load(a + i + 4);
    for (int k = 0; k < K; ++k) {
      low[k] += a_low * load(b - k + i);
      high[k] += a_high * load(b - k + i + 4);
    }
  }
  for (int l = 0; i < len; ++i, ++l)
    for (int k = 0; k < K; ++k) {
      if (l < 4)
        low[k][l] += a[i] * (b - k)[i];
      else
        high[k][l - 4] += a[i] * (b - k)[i];
    }
  for (int k = 0; k < K; ++k) out[k] += reduce_lanes(low[k], high[k]);
}

[[gnu::always_inline]] inline void lagged_dots_body(const double* a, const double* b,
                                                    std::size_t len, int count, double* out) {
  const auto n = static_cast<std::ptrdiff_t>(len);
  int j = 0;
  for (; j + 4 <= count; j += 4) lagged_dots_block<4>(a, b - j, n, out + j);
  switch (count - j) {
    case 3:
      lagged_dots_block<3>(a, b - j, n, out + j);
      break;
    case 2:
      lagged_dots_block<2>(a, b - j, n, out + j);
      break;
    case 1:
      lagged_dots_block<1>(a, b - j, n, out + j);
      break;
    default:
      break;
  }
}

// 16 rows in registers over all taps; taps in order j = 0, 1, ... for every row (the tail too).
[[gnu::always_inline]] inline void fir_body(const double* x, const double* w, int count,
                                            std::size_t len, double* out) {
  const auto n = static_cast<std::ptrdiff_t>(len);
  std::ptrdiff_t i = 0;
  for (; i + 16 <= n; i += 16) {
    V4 acc0 = load(out + i), acc1 = load(out + i + 4), acc2 = load(out + i + 8),
       acc3 = load(out + i + 12);
    for (int j = 0; j < count; ++j) {
      const V4 wj = V4{w[j], w[j], w[j], w[j]};
      const double* xj = x + i - j;
      acc0 -= wj * load(xj);
      acc1 -= wj * load(xj + 4);
      acc2 -= wj * load(xj + 8);
      acc3 -= wj * load(xj + 12);
    }
    store(out + i, acc0);
    store(out + i + 4, acc1);
    store(out + i + 8, acc2);
    store(out + i + 12, acc3);
  }
  for (; i < n; ++i) {
    double acc = out[i];
    for (int j = 0; j < count; ++j) acc -= w[j] * x[i - j];
    out[i] = acc;
  }
}

}  // namespace

namespace detail {

void add_lagged_dots_sse2(const double* a, const double* b, std::size_t len, int count,
                          double* out) {
  lagged_dots_body(a, b, len, count, out);
}
__attribute__((target("avx"))) void add_lagged_dots_avx(const double* a, const double* b,
                                                        std::size_t len, int count, double* out) {
  lagged_dots_body(a, b, len, count, out);
}
void subtract_fir_sse2(const double* x, const double* w, int count, std::size_t len, double* out) {
  fir_body(x, w, count, len, out);
}
__attribute__((target("avx"))) void subtract_fir_avx(const double* x, const double* w, int count,
                                                     std::size_t len, double* out) {
  fir_body(x, w, count, len, out);
}
bool cpu_has_avx() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx");
}

}  // namespace detail

void add_lagged_dots(const double* a, const double* b, std::size_t len, int count, double* out) {
  // Chosen on first use (not at static initialisation: callers may run before it).
  static const auto kernel =
      detail::cpu_has_avx() ? detail::add_lagged_dots_avx : detail::add_lagged_dots_sse2;
  kernel(a, b, len, count, out);
}

void subtract_fir(const double* x, const double* w, int count, std::size_t len, double* out) {
  static const auto kernel =
      detail::cpu_has_avx() ? detail::subtract_fir_avx : detail::subtract_fir_sse2;
  kernel(x, w, count, len, out);
}

}  // namespace imscal::ident
