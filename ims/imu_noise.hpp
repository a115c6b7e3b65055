#pragma once
// The stochastic sensor model: draws the deterministic errors of one unit from a SensorSpec and
// corrupts ideal samples with them plus noise. For each triad and increment sample k over dt:
//
//   raw_k = A * ideal_k + (b_turn_on + mean of b_GM over the interval) * dt + N * sqrt(dt) * w_k
//   then saturation: |raw_k| <= range * dt per axis,
//   then quantisation with the residual carried: out_k = LSB * round((raw_k + r_{k-1}) / LSB),
//        r_k = raw_k + r_{k-1} - out_k, so |sum of (out - raw)| <= LSB/2 however long the record.
//
// A and b_turn_on come from the SensorErrorModel (ims/sensor_error_model.hpp); w_k ~ N(0, I);
// N is the white noise density (ARW / VRW); each Gauss-Markov term is propagated exactly,
// b_k = rho b_{k-1} + sigma sqrt(1 - rho^2) v_k with rho = exp(-dt / tau), started from its
// stationary distribution, and enters the increment as (b_{k-1} + b_k) / 2 * dt (exact to
// O(dt / tau)). Saturation clamps the mean rate over the interval, not the instantaneous one.
// Rate series are treated as increments rate * dt and divided by dt again (white noise then has
// sigma N / sqrt(dt), the band-limited rate noise, and the LSB of a rate is LSB / dt).
//
// The in-run part (the sum of the Gauss-Markov terms, mean over each interval) can be handed
// back: it is part of the truth, since the bias a record shows drifts away from the turn-on
// bias by ~sigma sqrt(2 T / tau) over T seconds (5.5 ug over 110 s for 10 ug, 600 s).
//
// Determinism: normal draws are made by the polar method on std::mt19937_64 (fully specified
// by the standard), so a seed gives the same numbers with any standard library; same seed and
// same input give bit-identical output on the same platform.
#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <vector>

#include "ims/imu_data.hpp"
#include "ims/sensor_error_model.hpp"
#include "ims/sensor_spec.hpp"

namespace imscal::ims {

// Standard normal draws, Marsaglia's polar method (keeps the second value of each pair).
class NormalDraws {
 public:
  explicit NormalDraws(std::mt19937_64& rng) : rng_(rng) {}
  double next();

 private:
  std::mt19937_64& rng_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// Turn-on biases, scale factors and the six misalignment angles of each triad, each an
// independent zero-mean normal with the spec's sigma.
SensorErrorModel draw_sensor_errors(const SensorSpec& spec, std::mt19937_64& rng);

// The in-run bias of each triad over every sample's interval (the same time stamps as the
// series), beside the constant turn-on bias of the SensorErrorModel.
struct InRunBias {
  std::vector<double> t_s;
  std::vector<Eigen::Vector3d> gyro_rad_s;
  std::vector<Eigen::Vector3d> acc_m_s2;
};

// The ideal series (increments or rates) as the unit described by `errors` and `spec` would
// output it. Uses spec only for the noise, bias instability, quantisation and range (the
// deterministic errors are those in `errors`). in_run (may be null): receives the in-run bias;
// the draws, and so the output, are the same either way.
ImuSeries corrupt(const ImuSeries& ideal, const SensorErrorModel& errors, const SensorSpec& spec,
                  std::uint64_t seed, InRunBias* in_run = nullptr);

}  // namespace imscal::ims
