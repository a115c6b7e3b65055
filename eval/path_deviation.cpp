#include "eval/path_deviation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace imscal::eval {

PathDeviation path_deviation(const std::vector<TimedPoint>& desired,
                             const std::vector<TimedPoint>& actual, double window_s) {
  if (desired.size() < 2) throw std::invalid_argument("path_deviation: < 2 desired points");
  if (!(window_s > 0.0)) throw std::invalid_argument("path_deviation: window must be > 0");
  PathDeviation out;
  out.t_s.reserve(actual.size());
  out.deviation_m.reserve(actual.size());
  out.deviation_vector_m.reserve(actual.size());
  auto time_less = [](const TimedPoint& a, double t) { return a.t_s < t; };
  double sum_squares = 0.0;
  for (const TimedPoint& a : actual) {
    // Desired segments [k, k+1] with any end inside [t - window, t + window].
    auto first = std::lower_bound(desired.begin(), desired.end(), a.t_s - window_s, time_less);
    auto last = std::lower_bound(desired.begin(), desired.end(), a.t_s + window_s, time_less);
    std::size_t k0 = static_cast<std::size_t>(first - desired.begin());
    std::size_t k1 = static_cast<std::size_t>(last - desired.begin());
    k0 = k0 > 0 ? k0 - 1 : 0;
    k1 = std::min(k1 + 1, desired.size() - 1);
    if (k1 <= k0) {  // outside the desired path's time span: its nearest end segment
      k0 = a.t_s < desired.front().t_s ? 0 : desired.size() - 2;
      k1 = k0 + 1;
    }
    double best = std::numeric_limits<double>::infinity();
    Eigen::Vector3d best_vector = Eigen::Vector3d::Zero();
    for (std::size_t k = k0; k < k1; ++k) {
      const Eigen::Vector3d& p0 = desired[k].p_m;
      const Eigen::Vector3d segment = desired[k + 1].p_m - p0;
      const double length2 = segment.squaredNorm();
      const double u =
          length2 > 0.0 ? std::clamp((a.p_m - p0).dot(segment) / length2, 0.0, 1.0) : 0.0;
      const Eigen::Vector3d d = a.p_m - (p0 + u * segment);
      const double distance2 = d.squaredNorm();
      if (distance2 < best) {
        best = distance2;
        best_vector = d;
      }
    }
    const double distance = std::sqrt(best);
    if (out.deviation_m.empty() || distance > out.max_m) {
      out.max_m = distance;
      out.index_of_max = out.deviation_m.size();
    }
    sum_squares += best;
    out.t_s.push_back(a.t_s);
    out.deviation_m.push_back(distance);
    out.deviation_vector_m.push_back(best_vector);
  }
  out.rms_m = actual.empty() ? 0.0 : std::sqrt(sum_squares / static_cast<double>(actual.size()));
  return out;
}

namespace {

// The cycles' deviation vectors grouped by instant (key: time in 0.1 ms).
std::map<long long, std::vector<Eigen::Vector3d>> vectors_by_instant(
    const std::vector<PathDeviation>& cycles) {
  std::map<long long, std::vector<Eigen::Vector3d>> vectors_at;
  for (const PathDeviation& d : cycles)
    for (std::size_t k = 0; k < d.t_s.size(); ++k)
      vectors_at[std::llround(d.t_s[k] * 1e4)].push_back(d.deviation_vector_m[k]);
  return vectors_at;
}

}  // namespace

double scatter_floor_m(const std::vector<PathDeviation>& cycles) {
  return split_cycles(cycles).scatter_floor_m;
}

CycleSplit split_cycles(const std::vector<PathDeviation>& cycles) {
  CycleSplit split;
  for (const auto& [key, vectors] : vectors_by_instant(cycles)) {
    for (std::size_t a = 0; a < vectors.size(); ++a)
      for (std::size_t b = a + 1; b < vectors.size(); ++b)
        split.scatter_floor_m =
            std::max(split.scatter_floor_m, 0.5 * (vectors[a] - vectors[b]).norm());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& v : vectors) mean += v;
    mean /= double(vectors.size());
    split.systematic_max_m = std::max(split.systematic_max_m, mean.norm());
    for (const Eigen::Vector3d& v : vectors)
      split.about_mean_max_m = std::max(split.about_mean_max_m, (v - mean).norm());
  }
  return split;
}

}  // namespace imscal::eval
