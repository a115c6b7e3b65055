#include "eval/iso9283_path.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

namespace imscal::eval {
namespace {

// A calculation point on the commanded path.
struct CalculationPoint {
  double s_m = 0.0;
  double t_s = 0.0;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  Eigen::Vector3d tangent = Eigen::Vector3d::UnitX();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
};

struct Crossing {
  Eigen::Vector3d x;
  Eigen::Quaterniond q;
  double speed_m_s;
};

std::vector<CalculationPoint> calculation_points(const PoseSeries& commanded, int m,
                                                 double& length_m) {
  std::vector<double> s(commanded.size(), 0.0);
  for (std::size_t k = 1; k < commanded.size(); ++k) {
    if (!(commanded[k].t_s > commanded[k - 1].t_s)) {
      throw std::invalid_argument("iso9283_path: commanded times must increase");
    }
    s[k] = s[k - 1] + (commanded[k].p_m - commanded[k - 1].p_m).norm();
  }
  length_m = s.back();
  if (!(length_m > 0.0)) throw std::invalid_argument("iso9283_path: commanded path has no length");
  std::vector<CalculationPoint> points;
  std::size_t k = 0;
  for (int i = 0; i < m; ++i) {
    const double target = length_m * (i + 0.5) / m;  // mid-cells: never the path's ends
    while (k + 2 < s.size() && s[k + 1] < target) ++k;
    while (k + 2 < s.size() && s[k + 1] <= s[k]) ++k;  // skip rests (zero-length pieces)
    const double piece = s[k + 1] - s[k];
    const double u = piece > 0.0 ? std::clamp((target - s[k]) / piece, 0.0, 1.0) : 0.0;
    CalculationPoint p;
    p.s_m = target;
    p.t_s = commanded[k].t_s + u * (commanded[k + 1].t_s - commanded[k].t_s);
    p.c = commanded[k].p_m + u * (commanded[k + 1].p_m - commanded[k].p_m);
    p.tangent = (commanded[k + 1].p_m - commanded[k].p_m).normalized();
    p.q = commanded[k].q.slerp(u, commanded[k + 1].q);
    points.push_back(p);
  }
  return points;
}

// The attained path's crossing of the normal plane at `point` closest to it, within the window.
std::optional<Crossing> crossing(const PoseSeries& attained, const CalculationPoint& point,
                                 double window_s) {
  auto time_less = [](const PathPose& a, double t) { return a.t_s < t; };
  auto first = std::lower_bound(attained.begin(), attained.end(), point.t_s - window_s, time_less);
  auto last = std::lower_bound(attained.begin(), attained.end(), point.t_s + window_s, time_less);
  std::optional<Crossing> best;
  double best_distance = std::numeric_limits<double>::infinity();
  for (auto a = first; a != last && a + 1 != attained.end(); ++a) {
    const auto b = a + 1;
    const double fa = (a->p_m - point.c).dot(point.tangent);
    const double fb = (b->p_m - point.c).dot(point.tangent);
    if ((fa > 0.0 && fb > 0.0) || (fa < 0.0 && fb < 0.0) || fa == fb) continue;
    const double u = fa / (fa - fb);
    const Eigen::Vector3d x = a->p_m + u * (b->p_m - a->p_m);
    const double distance = (x - point.c).norm();
    if (distance < best_distance) {
      best_distance = distance;
      best = Crossing{x, a->q.slerp(u, b->q), (b->p_m - a->p_m).norm() / (b->t_s - a->t_s)};
    }
  }
  return best;
}

double sample_std(const std::vector<double>& values, double mean) {
  double sum = 0.0;
  for (double v : values) sum += (v - mean) * (v - mean);
  return std::sqrt(sum / static_cast<double>(values.size() - 1));
}

}  // namespace

Iso9283PathResult iso9283_path(const PoseSeries& commanded, const std::vector<PoseSeries>& attained,
                               double v_c_m_s, const Iso9283Options& options) {
  if (commanded.size() < 2) throw std::invalid_argument("iso9283_path: < 2 commanded poses");
  if (attained.empty()) throw std::invalid_argument("iso9283_path: no attained cycle");
  if (options.calculation_points < 1) throw std::invalid_argument("iso9283_path: m < 1");
  Iso9283PathResult r;
  r.cycles = static_cast<int>(attained.size());
  const std::vector<CalculationPoint> points =
      calculation_points(commanded, options.calculation_points, r.length_m);
  const double n = static_cast<double>(attained.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (attained.size() < 2) {
    r.RT_p_m = r.RV_percent = nan;
    r.RT_abc_rad.setConstant(nan);
  }
  const double v_from = options.velocity_from_m;
  const double v_to = options.velocity_to_m < 0.0 ? r.length_m : options.velocity_to_m;
  std::vector<std::vector<double>> speeds(attained.size());  // v_ij per cycle
  for (const CalculationPoint& point : points) {
    std::vector<Eigen::Vector3d> x;
    std::vector<Eigen::Vector3d> abc;
    for (std::size_t j = 0; j < attained.size(); ++j) {
      const std::optional<Crossing> found = crossing(attained[j], point, options.time_window_s);
      if (!found) {
        ++r.missed_crossings;
        continue;
      }
      x.push_back(found->x);
      const Eigen::AngleAxisd deviation(found->q * point.q.conjugate());
      abc.push_back(deviation.angle() * deviation.axis());
      if (point.s_m >= v_from && point.s_m <= v_to) speeds[j].push_back(found->speed_m_s);
    }
    if (x.size() != attained.size()) continue;  // ISO: every cycle at every point
    Eigen::Vector3d x_bar = Eigen::Vector3d::Zero(), abc_bar = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < x.size(); ++j) {
      x_bar += x[j] / n;
      abc_bar += abc[j] / n;
    }
    const double accuracy = (x_bar - point.c).norm();
    r.arc_length_m.push_back(point.s_m);
    r.commanded_m.push_back(point.c);
    r.accuracy_m.push_back(accuracy);
    r.AT_p_m = std::max(r.AT_p_m, accuracy);
    r.AT_abc_rad = r.AT_abc_rad.cwiseMax(abc_bar.cwiseAbs());
    if (x.size() < 2) continue;
    std::vector<double> l(x.size());
    for (std::size_t j = 0; j < x.size(); ++j) l[j] = (x[j] - x_bar).norm();
    double l_bar = 0.0;
    for (double v : l) l_bar += v / n;
    r.RT_p_m = std::max(r.RT_p_m, l_bar + 3.0 * sample_std(l, l_bar));
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> angle(x.size());
      for (std::size_t j = 0; j < x.size(); ++j) angle[j] = abc[j][axis];
      r.RT_abc_rad[axis] = std::max(r.RT_abc_rad[axis], 3.0 * sample_std(angle, abc_bar[axis]));
    }
  }
  if (r.accuracy_m.empty()) {
    throw std::invalid_argument("iso9283_path: no calculation point was crossed by every cycle");
  }
  if (v_c_m_s > 0.0) {
    std::vector<double> cycle_means;
    for (const std::vector<double>& v : speeds) {
      if (v.empty()) throw std::invalid_argument("iso9283_path: no speed in the velocity range");
      double mean = 0.0;
      for (double value : v) mean += value / static_cast<double>(v.size());
      cycle_means.push_back(mean);
      const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
      r.FV_m_s = std::max(r.FV_m_s, *hi - *lo);
    }
    double v_bar = 0.0;
    for (double mean : cycle_means) v_bar += mean / n;
    r.AV_percent = (v_bar - v_c_m_s) / v_c_m_s * 100.0;
    if (cycle_means.size() >= 2) {
      r.RV_percent = 3.0 * sample_std(cycle_means, v_bar) / v_c_m_s * 100.0;
    }
  } else {
    r.AV_percent = r.RV_percent = r.FV_m_s = nan;
  }
  return r;
}

Iso9283CornerResult iso9283_corner(const Eigen::Vector3d& start, const Eigen::Vector3d& corner,
                                   const Eigen::Vector3d& end,
                                   const std::vector<PoseSeries>& attained) {
  const Eigen::Vector3d d1 = (corner - start).normalized();
  const Eigen::Vector3d d2 = (end - corner).normalized();
  const double length2 = (end - corner).norm();
  Eigen::Vector3d outside = d1 - d1.dot(d2) * d2;  // the first leg's motion, across the second
  if (!(outside.norm() > 1e-9) || attained.empty()) {
    throw std::invalid_argument("iso9283_corner: legs must form a corner, >= 1 cycle");
  }
  outside.normalize();
  Iso9283CornerResult r;
  for (const PoseSeries& cycle : attained) {
    double round_off = std::numeric_limits<double>::infinity();
    double overshoot = 0.0;
    for (std::size_t k = 0; k < cycle.size(); ++k) {
      const Eigen::Vector3d& p = cycle[k].p_m;
      if (k + 1 < cycle.size()) {  // distance from the corner to the attained polyline
        const Eigen::Vector3d segment = cycle[k + 1].p_m - p;
        const double u =
            segment.squaredNorm() > 0.0
                ? std::clamp((corner - p).dot(segment) / segment.squaredNorm(), 0.0, 1.0)
                : 0.0;
        round_off = std::min(round_off, (p + u * segment - corner).norm());
      }
      const double along = (p - corner).dot(d2);
      if (along >= 0.0 && along <= length2) {
        overshoot = std::max(overshoot, (p - corner).dot(outside));
      }
    }
    r.CR_m = std::max(r.CR_m, round_off);
    r.CO_m = std::max(r.CO_m, overshoot);
  }
  return r;
}

}  // namespace imscal::eval
