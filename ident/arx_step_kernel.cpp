#include "ident/arx_step_kernel.hpp"

#include <immintrin.h>

namespace imscal::ident {
namespace {

static_assert(kArxStepLanes == 8, "the kernels below hold 8 partial sums per sum");

// The fixed reduction tree of 8 partial sums (shared by both kernels: same rounding).
double reduce(const double* sum) noexcept {
  const double s0 = sum[0] + sum[4], s1 = sum[1] + sum[5];
  const double s2 = sum[2] + sum[6], s3 = sum[3] + sum[7];
  return (s0 + s2) + (s1 + s3);
}

// sum[l] += Σ_{i ≡ l mod 8, i < terms} coefficient[i] v[i], the 8 partial sums held in 4 SSE2
// registers.
inline void add_sse2(__m128d (&sum)[4], const double* coefficient, const double* v,
                     int terms) noexcept {
  for (int i = 0; i < terms; i += kArxStepLanes) {
    const double *k = coefficient + i, *x = v + i;
    sum[0] = _mm_add_pd(sum[0], _mm_mul_pd(_mm_loadu_pd(k), _mm_loadu_pd(x)));
    sum[1] = _mm_add_pd(sum[1], _mm_mul_pd(_mm_loadu_pd(k + 2), _mm_loadu_pd(x + 2)));
    sum[2] = _mm_add_pd(sum[2], _mm_mul_pd(_mm_loadu_pd(k + 4), _mm_loadu_pd(x + 4)));
    sum[3] = _mm_add_pd(sum[3], _mm_mul_pd(_mm_loadu_pd(k + 6), _mm_loadu_pd(x + 6)));
  }
}

inline double reduce_sse2(const __m128d (&sum)[4]) noexcept {
  alignas(16) double lane[8];
  for (int r = 0; r < 4; ++r) _mm_store_pd(lane + 2 * r, sum[r]);
  return reduce(lane);
}

void steps_sse2(const ArxCellCoefficients* cells, const double* const* y_past, int count,
                const ArxInputWindows& inputs, double* output) noexcept {
  for (int c = 0; c < count; ++c) {
    const ArxCellCoefficients& m = cells[c];
    __m128d in[4] = {_mm_setzero_pd(), _mm_setzero_pd(), _mm_setzero_pd(), _mm_setzero_pd()};
    __m128d out[4] = {in[0], in[0], in[0], in[0]};
    add_sse2(in, m.b.data(), inputs.u + m.dead_time, m.b_terms);
    for (int e = 0; e < inputs.extra_count; ++e)
      add_sse2(in, m.c[e].data(), inputs.x[e] + m.dead_time, m.c_terms[e]);
    add_sse2(out, m.a.data(), y_past[c], m.a_terms);
    output[c] = reduce_sse2(in) - reduce_sse2(out);
  }
}

// The same 8 partial sums in 2 AVX registers.
__attribute__((target("avx"))) inline void add_avx(__m256d (&sum)[2], const double* coefficient,
                                                   const double* v, int terms) noexcept {
  for (int i = 0; i < terms; i += kArxStepLanes) {
    const double *k = coefficient + i, *x = v + i;
    sum[0] = _mm256_add_pd(sum[0], _mm256_mul_pd(_mm256_loadu_pd(k), _mm256_loadu_pd(x)));
    sum[1] = _mm256_add_pd(sum[1], _mm256_mul_pd(_mm256_loadu_pd(k + 4), _mm256_loadu_pd(x + 4)));
  }
}

__attribute__((target("avx"))) inline double reduce_avx(const __m256d (&sum)[2]) noexcept {
  alignas(32) double lane[8];
  _mm256_store_pd(lane, sum[0]), _mm256_store_pd(lane + 4, sum[1]);
  return reduce(lane);
}

__attribute__((target("avx"))) void steps_avx(const ArxCellCoefficients* cells,
                                              const double* const* y_past, int count,
                                              const ArxInputWindows& inputs,
                                              double* output) noexcept {
  for (int c = 0; c < count; ++c) {
    const ArxCellCoefficients& m = cells[c];
    __m256d in[2] = {_mm256_setzero_pd(), _mm256_setzero_pd()};
    __m256d out[2] = {in[0], in[0]};
    add_avx(in, m.b.data(), inputs.u + m.dead_time, m.b_terms);
    for (int e = 0; e < inputs.extra_count; ++e)
      add_avx(in, m.c[e].data(), inputs.x[e] + m.dead_time, m.c_terms[e]);
    add_avx(out, m.a.data(), y_past[c], m.a_terms);
    output[c] = reduce_avx(in) - reduce_avx(out);
  }
}

using StepsKernel = void (*)(const ArxCellCoefficients*, const double* const*, int,
                             const ArxInputWindows&, double*) noexcept;

StepsKernel choose_kernel() noexcept {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx") ? steps_avx : steps_sse2;
}

// Chosen once at start-up (static initialisation), read-only afterwards.
const StepsKernel kKernel = choose_kernel();

}  // namespace

void arx_free_run_steps(const ArxCellCoefficients* cells, const double* const* y_past, int count,
                        const ArxInputWindows& inputs, double* output) noexcept {
  kKernel(cells, y_past, count, inputs, output);
}

const char* arx_step_kernel_name() noexcept {
  return kKernel == steps_avx ? "avx" : "sse2";
}

}  // namespace imscal::ident
