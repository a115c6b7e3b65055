#pragma once
// Zero-velocity-aided smoothing of a strapdown record with pauses (robot motions that stop now
// and then): the sensor pose W_T_S(t) with its 1-sigma, and the sensor biases.
//
// 1. Rest detection from the IMS alone (ims/rest_detector.hpp).
// 2. Forward pass: the nominal trajectory is mechanised by ims::Strapdown from the increments
//    corrected by the current bias estimates; an error-state Kalman filter
//    (ims/error_state_model.hpp, 15 states) propagates the error covariance once per
//    `propagation_interval_s` and updates with
//      zero velocity:      0 = v_W, at the end of every propagation interval inside a rest
//                          (sigma: zero_velocity_sigma (+) velocity quantisation LSB/sqrt(12));
//      zero angular rate:  0 = mean gyro rate - b_g - R_S_W omega_ie, once per rest over its
//                          interior (sigma^2: ARW^2/T + LSB^2/(6 T^2) + zero_angular_rate_sigma^2).
//    Updates whose normalised innovation squared exceeds the gate are rejected. The estimate is
//    fed back into the nominal state and the bias estimates after every update (closed loop),
//    so the error stays small and the linear model holds.
//    With SmootherAids (ims/smoother_aids.hpp): the rests only where the aid says the sensor is
//    still, and velocity measurements v_W = v_aid + noise(sigma) at the propagation instants
//    the aid covers (gated like the zero-velocity updates).
// 3. Backward pass: Rauch-Tung-Striebel on the error state, with the filter's stored covariances
//    and transitions; the smoothed errors are applied to the nominal trajectory, interpolated
//    linearly between propagation instants.
//
// Rests make velocity, the gyro biases (with the Earth rate) and, through the changes of
// attitude between rests, roll, pitch and the accelerometer biases observable. Heading is
// observable only through the Earth rate (gyrocompassing, slow); position not at all: its error
// is that of the initial position plus the integrated motion errors.
//
// References (docs/references.md): [Groves2013] (error-state filter, zero-velocity and
// zero-angular-rate updates), [RTS1965] (backward pass).
#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"
#include "ims/nav_state.hpp"
#include "ims/rest_detector.hpp"
#include "ims/smoother_aids.hpp"
#include "ims/zupt_options.hpp"

namespace imscal::ims {

// One sample of the smoothed trajectory.
struct SmoothedState {
  NavState state;  // W_T_S at state.t_s, velocity in W
  // 1-sigma of the attitude error in W [rad] (phi of ims/error_state_model.hpp), the velocity
  // [m/s] and the position [m].
  Eigen::Matrix<double, 9, 1> sigma = Eigen::Matrix<double, 9, 1>::Zero();
};

// Smoothed biases at one propagation instant.
struct SmoothedBias {
  double t_s = 0.0;
  Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc_m_s2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_sigma_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc_sigma_m_s2 = Eigen::Vector3d::Zero();
};

struct InnovationStatistics {
  std::size_t accepted = 0;
  std::size_t rejected = 0;        // by the gate
  double mean_nis = 0.0;           // over the accepted updates; 3 expected (3 components)
  double fraction_above_95 = 0.0;  // share of accepted NIS above the chi-square(3) 95% quantile
};

struct ZuptSummary {
  std::vector<RestInterval> rest_intervals;
  InnovationStatistics zero_velocity;
  InnovationStatistics zero_angular_rate;
  InnovationStatistics velocity_aid;  // SmootherAids::velocity
  std::size_t propagation_steps = 0;
};

// The smoothed states one block at a time, in sample order: mechanised again from the initial
// state with the forward pass' bias estimates and feedbacks and corrected by the smoothed
// errors of the propagation instants around each sample. What the states are built from (about
// 550 bytes per 10 ms) waits in temporary files (ims/zupt_smoother_records.hpp), so a caller
// that uses the trajectory block by block holds memory that does not grow with the record.
// Holds a view of the IMS record it was smoothed from, which must outlive it.
class SmoothedStateStream {
 public:
  struct Record;  // the forward and backward passes' per-instant results (zupt_smoother.cpp)
  SmoothedStateStream();  // no states
  SmoothedStateStream(std::unique_ptr<Record> record, ImuSamples imu);
  ~SmoothedStateStream();
  SmoothedStateStream(SmoothedStateStream&&) noexcept;
  SmoothedStateStream& operator=(SmoothedStateStream&&) noexcept;

  // Appends the next states, at most `max_states`, to `out`; returns how many.
  std::size_t next(std::vector<SmoothedState>& out, std::size_t max_states);
  bool done() const;
  // Starts again at the first sample (for a second pass over the trajectory).
  void rewind();
  std::size_t size() const;  // states in all: one per IMS sample
  // The smoothed biases, one per propagation instant (read from the files; the cursor stays).
  std::vector<SmoothedBias> biases();

 private:
  struct Cursor;
  ImuSamples imu_;  // a view of the record smoothed
  std::unique_ptr<Record> record_;
  std::unique_ptr<Cursor> cursor_;
};

struct ZuptSmoothing {
  SmoothedStateStream states;  // and the smoothed biases (SmoothedStateStream::biases)
  ZuptSummary summary;
};

struct ZuptSmootherResult {
  // One per IMS sample, at the sample's time stamp; with room for one more (a caller's initial
  // state goes in front without a copy of the states).
  std::vector<SmoothedState> states;
  std::vector<SmoothedBias> biases;  // one per propagation instant
  ZuptSummary summary;
};

// `initial`: navigation state at the start of the first increment (samples[0].t_s - its
// interval); `initial_sigma`: its 1-sigma (attitude [rad] in W, velocity, position).
// Needs increments; throws InputError otherwise, or for inconsistent options.
// The same smoothing with the states as a stream (ZuptSmoothing::states); the record `imu` views
// must outlive it.
ZuptSmoothing smooth_with_zupt_streamed(const ImuSamples& imu, const EarthModel& earth,
                                        const NavState& initial,
                                        const Eigen::Matrix<double, 9, 1>& initial_sigma,
                                        const ZuptOptions& options, const SmootherAids& aids = {});

ZuptSmootherResult smooth_with_zupt(const ImuSamples& imu, const EarthModel& earth,
                                    const NavState& initial,
                                    const Eigen::Matrix<double, 9, 1>& initial_sigma,
                                    const ZuptOptions& options, const SmootherAids& aids = {});

}  // namespace imscal::ims
