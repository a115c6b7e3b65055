#pragma once
// The two kernels of the ARX least squares that touch every sample (ident/arx_fit.cpp): the
// dot products of a signal with lagged copies of another (the Gram matrix's correlation sums,
// Φᵀr) and a finite impulse response subtracted from a block (the residual r = y - Φθ).
//
// Why kernels of their own: a regressor matrix of lagged copies is never formed, so a row block
// meets each coefficient once as a dot product or an axpy over the block. Done one lag at a time
// each multiply-add costs two loads (Eigen's dot) or three memory operations (axpy); here four
// lags share each load of the first signal, and the FIR keeps sixteen rows in registers over
// all its taps: ~3x fewer memory operations. Both are compiled for SSE2 (every x86-64) and for
// AVX (chosen at start-up), without fused multiply-adds: every output sums its terms in one
// fixed order (lanes of 8 entries, a fixed reduction tree; the FIR's taps in order), so the
// result is bitwise the same on every machine and at every vector width.
#include <cstddef>

namespace imscal::ident {

// out[j] += Σ_{i < len} a[i] · b[i - j] for j = 0 .. count - 1 (b[-count+1 .. len-1] readable).
void add_lagged_dots(const double* a, const double* b, std::size_t len, int count, double* out);

// out[i] -= Σ_{j < count} w[j] · x[i - j] for i = 0 .. len - 1 (x[-count+1 .. len-1] readable);
// the taps are subtracted in the order j = 0, 1, ...
void subtract_fir(const double* x, const double* w, int count, std::size_t len, double* out);

namespace detail {
// The two builds of each kernel, for the test that they agree bitwise (the AVX ones only where
// cpu_has_avx()).
void add_lagged_dots_sse2(const double* a, const double* b, std::size_t len, int count,
                          double* out);
void add_lagged_dots_avx(const double* a, const double* b, std::size_t len, int count, double* out);
void subtract_fir_sse2(const double* x, const double* w, int count, std::size_t len, double* out);
void subtract_fir_avx(const double* x, const double* w, int count, std::size_t len, double* out);
bool cpu_has_avx();
}  // namespace detail

}  // namespace imscal::ident
