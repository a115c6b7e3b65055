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

void steps_sse2(const ArxStepInput* models, int count, double* output) noexcept {
  for (int c = 0; c < count; ++c) {
    const ArxStepInput& m = models[c];
    __m128d in0 = _mm_setzero_pd(), in1 = in0, in2 = in0, in3 = in0;
    __m128d out0 = in0, out1 = in0, out2 = in0, out3 = in0;
    for (int i = 0; i < m.terms; i += kArxStepLanes) {
      const double *b = m.b + i, *u = m.u_delayed + i, *a = m.a + i, *y = m.y_past + i;
      in0 = _mm_add_pd(in0, _mm_mul_pd(_mm_loadu_pd(b), _mm_loadu_pd(u)));
      in1 = _mm_add_pd(in1, _mm_mul_pd(_mm_loadu_pd(b + 2), _mm_loadu_pd(u + 2)));
      in2 = _mm_add_pd(in2, _mm_mul_pd(_mm_loadu_pd(b + 4), _mm_loadu_pd(u + 4)));
      in3 = _mm_add_pd(in3, _mm_mul_pd(_mm_loadu_pd(b + 6), _mm_loadu_pd(u + 6)));
      out0 = _mm_add_pd(out0, _mm_mul_pd(_mm_loadu_pd(a), _mm_loadu_pd(y)));
      out1 = _mm_add_pd(out1, _mm_mul_pd(_mm_loadu_pd(a + 2), _mm_loadu_pd(y + 2)));
      out2 = _mm_add_pd(out2, _mm_mul_pd(_mm_loadu_pd(a + 4), _mm_loadu_pd(y + 4)));
      out3 = _mm_add_pd(out3, _mm_mul_pd(_mm_loadu_pd(a + 6), _mm_loadu_pd(y + 6)));
    }
    for (int e = 0; e < m.extra_count; ++e) {
      for (int i = 0; i < m.terms; i += kArxStepLanes) {
        const double *c = m.c[e] + i, *x = m.x_delayed[e] + i;
        in0 = _mm_add_pd(in0, _mm_mul_pd(_mm_loadu_pd(c), _mm_loadu_pd(x)));
        in1 = _mm_add_pd(in1, _mm_mul_pd(_mm_loadu_pd(c + 2), _mm_loadu_pd(x + 2)));
        in2 = _mm_add_pd(in2, _mm_mul_pd(_mm_loadu_pd(c + 4), _mm_loadu_pd(x + 4)));
        in3 = _mm_add_pd(in3, _mm_mul_pd(_mm_loadu_pd(c + 6), _mm_loadu_pd(x + 6)));
      }
    }
    alignas(16) double in[8], out[8];
    _mm_store_pd(in, in0), _mm_store_pd(in + 2, in1), _mm_store_pd(in + 4, in2);
    _mm_store_pd(in + 6, in3);
    _mm_store_pd(out, out0), _mm_store_pd(out + 2, out1), _mm_store_pd(out + 4, out2);
    _mm_store_pd(out + 6, out3);
    output[c] = reduce(in) - reduce(out);
  }
}

__attribute__((target("avx"))) void steps_avx(const ArxStepInput* models, int count,
                                              double* output) noexcept {
  alignas(32) double in[8], out[8];
  for (int c = 0; c < count; ++c) {
    const ArxStepInput& m = models[c];
    __m256d in0 = _mm256_setzero_pd(), in1 = in0, out0 = in0, out1 = in0;
    for (int i = 0; i < m.terms; i += kArxStepLanes) {
      const double *b = m.b + i, *u = m.u_delayed + i, *a = m.a + i, *y = m.y_past + i;
      in0 = _mm256_add_pd(in0, _mm256_mul_pd(_mm256_loadu_pd(b), _mm256_loadu_pd(u)));
      in1 = _mm256_add_pd(in1, _mm256_mul_pd(_mm256_loadu_pd(b + 4), _mm256_loadu_pd(u + 4)));
      out0 = _mm256_add_pd(out0, _mm256_mul_pd(_mm256_loadu_pd(a), _mm256_loadu_pd(y)));
      out1 = _mm256_add_pd(out1, _mm256_mul_pd(_mm256_loadu_pd(a + 4), _mm256_loadu_pd(y + 4)));
    }
    for (int e = 0; e < m.extra_count; ++e) {
      for (int i = 0; i < m.terms; i += kArxStepLanes) {
        const double *c = m.c[e] + i, *x = m.x_delayed[e] + i;
        in0 = _mm256_add_pd(in0, _mm256_mul_pd(_mm256_loadu_pd(c), _mm256_loadu_pd(x)));
        in1 = _mm256_add_pd(in1, _mm256_mul_pd(_mm256_loadu_pd(c + 4), _mm256_loadu_pd(x + 4)));
      }
    }
    _mm256_store_pd(in, in0), _mm256_store_pd(in + 4, in1);
    _mm256_store_pd(out, out0), _mm256_store_pd(out + 4, out1);
    output[c] = reduce(in) - reduce(out);
  }
}

using StepsKernel = void (*)(const ArxStepInput*, int, double*) noexcept;

StepsKernel choose_kernel() noexcept {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx") ? steps_avx : steps_sse2;
}

// Chosen once at start-up (static initialisation), read-only afterwards.
const StepsKernel kKernel = choose_kernel();

}  // namespace

void arx_free_run_steps(const ArxStepInput* models, int count, double* output) noexcept {
  kKernel(models, count, output);
}

const char* arx_step_kernel_name() noexcept {
  return kKernel == steps_avx ? "avx" : "sse2";
}

}  // namespace imscal::ident
