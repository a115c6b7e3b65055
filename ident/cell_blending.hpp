#pragma once
// Blending of neighbouring operating-point cells, for a real-time caller (the precontrol's 2 ms
// cycle): no allocation, no exceptions, bounded work (at most 2^kMaxCellDimensions corners).
//
// Each dimension of the cell grid has m cell centres c_0 < .. < c_{m-1}. For an operating point
// x the weights are multilinear between the centres of the neighbouring cells: in one dimension
// with c_i <= x < c_{i+1}, t = (x - c_i) / (c_{i+1} - c_i), cell i gets 1 - t and cell i+1 gets t;
// outside [c_0, c_{m-1}] the outermost cell gets 1 (constant extrapolation). In D dimensions the
// weight of a corner is the product of its per-dimension weights (2^D corners, weights sum to 1).
// The weights are continuous in x, so the blended correction Σ w_c Δq̂_c (each cell model c run in
// parallel on the desired angles) moves continuously when the operating point crosses a cell
// boundary, and equals cell c's own correction at its centre.
//
// Cells are numbered row-major: flat = Σ_d index_d · stride_d, the last dimension fastest.
#include <array>
#include <cstddef>
#include <span>

namespace imscal::ident {

inline constexpr int kMaxCellDimensions = 4;
inline constexpr int kMaxBlendCorners = 1 << kMaxCellDimensions;

struct CellBlend {
  int count = 0;  // corners with a weight (1 .. 2^D)
  // Only the first `count` entries are set: zeroing all of them cost the precontrol's cycle
  // ~30 ns per joint (a `rep stos` of 200 bytes), for entries nobody reads.
  std::array<int, kMaxBlendCorners> cell;       // flat cell index of each corner
  std::array<double, kMaxBlendCorners> weight;  // sums to 1
};

// centres[d]: the cell centres of dimension d (strictly increasing, at least one);
// point[d]: the operating point in the same units. Returns count = 0 when the dimension counts
// disagree or exceed kMaxCellDimensions (the caller's configuration error; checked on loading).
inline CellBlend blend_cells(std::span<const std::span<const double>> centres,
                             std::span<const double> point) noexcept {
  CellBlend out;
  const std::size_t dims = centres.size();
  if (dims != point.size() || dims > std::size_t(kMaxCellDimensions)) return out;
  std::array<int, kMaxCellDimensions> low{}, stride{};
  std::array<double, kMaxCellDimensions> upper_weight{};
  int s = 1;
  for (std::size_t d = dims; d-- > 0;) {
    stride[d] = s;
    const auto& c = centres[d];
    const int m = static_cast<int>(c.size());
    if (m == 0) return out;
    s *= m;
    const double x = point[d];
    if (!(x > c[0])) {  // also NaN: the lowest cell, so the caller always gets a defined answer
      low[d] = 0;
      upper_weight[d] = 0.0;
    } else if (x >= c[m - 1]) {
      low[d] = m - 1;
      upper_weight[d] = 0.0;
    } else {
      int i = 0;
      while (i + 2 < m && x >= c[i + 1]) ++i;  // m is small (a handful of bands)
      low[d] = i;
      upper_weight[d] = (x - c[i]) / (c[i + 1] - c[i]);
    }
  }
  const int corners = 1 << dims;
  for (int corner = 0; corner < corners; ++corner) {
    double w = 1.0;
    int flat = 0;
    for (std::size_t d = 0; d < dims; ++d) {
      const bool up = (corner >> d) & 1;
      if (up && upper_weight[d] == 0.0) {
        w = 0.0;
        break;
      }
      w *= up ? upper_weight[d] : 1.0 - upper_weight[d];
      flat += (low[d] + (up ? 1 : 0)) * stride[d];
    }
    if (w == 0.0) continue;
    out.cell[out.count] = flat;
    out.weight[out.count] = w;
    ++out.count;
  }
  return out;
}

}  // namespace imscal::ident
