#pragma once
// Path deviation as ISO 9283 (clause 8.2) measures path accuracy: the distance from each point of
// the actual path to the desired path, measured perpendicular to the desired path (the closest
// point of it), not to the desired point of the same instant. So a robot that follows the right
// line late has no path deviation, only a time lag.
//
// The desired path is a polyline through densely sampled desired positions (the interpolator's
// cycle); between samples it is straight, so on a curve of radius r sampled every ds the chord
// lies up to ds^2 / (8 r) inside the curve (0.4 m/s, 2 ms, r = 0.1 m: 8e-7 m).
// Each actual point is compared only with the desired path within +-window_s of its own time,
// so that paths that come back along themselves (the paper's line there and back) or cross
// themselves are not matched to the wrong pass.
//
// References (docs/references.md): [ISO9283] (clause 8.2).
#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace imscal::eval {

struct TimedPoint {
  double t_s = 0.0;
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();
};

struct PathDeviation {
  std::vector<double> t_s;                          // actual samples' times
  std::vector<double> deviation_m;                  // distance to the desired path [m]
  std::vector<Eigen::Vector3d> deviation_vector_m;  // from the closest desired point to the actual
  double max_m = 0.0;
  double rms_m = 0.0;
  std::size_t index_of_max = 0;
};

// desired, actual: strictly increasing times. Throws std::invalid_argument for fewer than two
// desired points or a non-positive window.
PathDeviation path_deviation(const std::vector<TimedPoint>& desired,
                             const std::vector<TimedPoint>& actual, double window_s = 1.0);

// The scatter of n cycles of the same path as a floor under their max deviation: at each instant
// (samples of the cycles matched by time to 0.1 ms), half the widest distance between two cycles'
// deviation vectors; the max over the instants [m]. A command that is the same in every cycle
// moves all of their points alike, so no such command gets the max deviation over the cycles
// below this, as long as the scatter does not change with the command. 0 for < 2 cycles.
double scatter_floor_m(const std::vector<PathDeviation>& cycles);

// The cycles' deviations split into what repeats and what does not, at each instant (matched as
// for the floor): the mean of the cycles' deviation vectors, which a command the same in every
// cycle can remove, and each cycle's distance from that mean, which it cannot; with the scatter
// floor of the same instants (one grouping of the cycles for all three). [m]
struct CycleSplit {
  double scatter_floor_m = 0.0;   // as scatter_floor_m()
  double systematic_max_m = 0.0;  // max over the instants of |mean vector|: the model's own error
  // max over instants and cycles of |vector - mean|: what a precontrol exact on average (the
  // mean removed at every instant) leaves as the max deviation; >= the scatter floor, which a
  // precontrol aiming at the middle of the spread instead of its mean would reach.
  double about_mean_max_m = 0.0;
};
CycleSplit split_cycles(const std::vector<PathDeviation>& cycles);

}  // namespace imscal::eval
