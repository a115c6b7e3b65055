#pragma once
// The inner loop of the precontrol (ident/precontrol.hpp): one free-run step of the ARX models
// of the cells of one joint (paper, eq. 2, with the further inputs of ident/arx_structure.hpp),
//
//   q̂(k) = Σ_{j<nb} b_j q_d(k-d-j) + Σ_e Σ_{j<nx_e} c_e,j x_e(k-d-j) - Σ_{i<na} a_{i+1} q̂(k-1-i),
//
// every sum over its own length rounded up to kArxStepLanes (the coefficients are stored with
// zeros past na, nb, nx_e, and the caller's histories are long enough to be read that far). A
// sum's length is its own, not the longest of the model's: a one-tap input (the torque's sign)
// costs one block of kArxStepLanes products, not max(na, nb, nx) of them.
//
// Each of the two sums (inputs, outputs) is kept as kArxStepLanes partial sums (entry i of an
// input's window goes to partial sum i mod 8; the inputs one after the other, main input first),
// reduced by a fixed tree at the end: independent chains that fill the SIMD units instead of one
// chain of dependent multiply-adds. The same partial sums are computed with 2-wide (SSE2, every
// x86-64) or 4-wide (AVX, chosen at start-up when the CPU has it) registers and no fused
// multiply-add, so the result is bitwise the same on every x86-64 machine. It differs from a
// plain loop (and from Eigen's dot) only by the order of the additions: a few ulp.
#include <array>

namespace imscal::ident {

inline constexpr int kArxStepLanes = 8;
inline constexpr int kArxStepMaxTerms = 64;  // longest sum (na, nb, nx_e), after rounding
inline constexpr int kArxStepMaxExtras = 11;
static_assert(kArxStepMaxTerms % kArxStepLanes == 0);

// One cell's model, fixed after construction. The coefficients live here, not behind pointers,
// so that the owner can be copied; they are aligned so that no coefficient block of the SIMD
// loops straddles a cache line.
struct alignas(64) ArxCellCoefficients {
  std::array<double, kArxStepMaxTerms> a{};  // a_1..a_na, then zeros
  std::array<double, kArxStepMaxTerms> b{};  // b_0..b_{nb-1}, then zeros
  // Further inputs' coefficients c_e,0..c_e,nx_e-1, then zeros.
  std::array<std::array<double, kArxStepMaxTerms>, kArxStepMaxExtras> c{};
  int dead_time = 0;  // d [samples]
  // Length of each sum: na, nb, nx_e rounded up to kArxStepLanes.
  int a_terms = 0, b_terms = 0;
  std::array<int, kArxStepMaxExtras> c_terms{};
};

// The newest-first input windows that all cells of a joint share: u[i] = q_d(k - i) and
// x[e][i] = x_e(k - i), each readable up to index d + (sum length) - 1 of every cell.
struct ArxInputWindows {
  const double* u = nullptr;
  std::array<const double*, kArxStepMaxExtras> x{};
  int extra_count = 0;  // further inputs (the same for every cell of the table)
};

// output[c] = q̂(k) of cells[c], c < count, with y_past[c][i] = q̂_c(k - 1 - i).
// No allocation, no exception.
void arx_free_run_steps(const ArxCellCoefficients* cells, const double* const* y_past, int count,
                        const ArxInputWindows& inputs, double* output) noexcept;

// The register width in use ("avx" or "sse2"), for reports.
const char* arx_step_kernel_name() noexcept;

}  // namespace imscal::ident
