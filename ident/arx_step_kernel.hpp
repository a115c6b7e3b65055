#pragma once
// The inner loop of the precontrol (ident/precontrol.hpp): one free-run step of several ARX
// models (paper, eq. 2),
//
//   q̂(k) = Σ_{j<terms} b_j q_d(k-d-j) [+ Σ_e Σ_{j<terms} c_e,j x_e(k-d-j)] - Σ_{i<terms} a_{i+1}
//   q̂(k-1-i),
//
// both sums over `terms` entries, a multiple of kArxStepLanes (the caller pads a and b with
// zeros past na and nb, and its histories are long enough to be read that far).
//
// Each sum is kept as kArxStepLanes partial sums (entry i goes to partial sum i mod 8), reduced
// by a fixed tree at the end: independent chains that fill the SIMD units instead of one chain
// of dependent multiply-adds. The same partial sums are computed with 2-wide (SSE2, every x86-64)
// or 4-wide (AVX, chosen at start-up when the CPU has it) registers and no fused multiply-add,
// so the result is bitwise the same on every x86-64 machine. It differs from a plain loop (and
// from Eigen's dot) only by the order of the additions: a few ulp.
namespace imscal::ident {

inline constexpr int kArxStepLanes = 8;

inline constexpr int kArxStepMaxExtras = 3;

struct ArxStepInput {
  const double* b;          // b_0 .. b_{terms-1}
  const double* u_delayed;  // u_delayed[j] = q_d(k - d - j)
  const double* a;          // a_1 .. a_terms
  const double* y_past;     // y_past[i] = q̂(k - 1 - i)
  int terms;                // multiple of kArxStepLanes
  // Further inputs of the multi-input form: + Σ_j c_e[j] x_e[j] over the same `terms` entries
  // (x_e[j] = x_e(k - d - j)), added to the input partial sums after the main input's.
  int extra_count = 0;
  const double* c[kArxStepMaxExtras] = {};
  const double* x_delayed[kArxStepMaxExtras] = {};
};

// output[c] = q̂(k) of models[c], c < count. No allocation, no exception.
void arx_free_run_steps(const ArxStepInput* models, int count, double* output) noexcept;

// The register width in use ("avx" or "sse2"), for reports.
const char* arx_step_kernel_name() noexcept;

}  // namespace imscal::ident
