#pragma once
// What the ZUPT smoother (ims/zupt_smoother.cpp) keeps per propagation instant, in temporary
// files (core/record_file.hpp) instead of memory, so that the smoother's memory does not grow
// with the record: the forward pass' instants (184 bytes each), their covariances (5.4 kB), and
// the backward pass' smoothed errors (360 bytes), 33 MB per recorded minute at 100 Hz in all.
// Each file holds one record per instant, written once in order and read back bit for bit.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

#include "core/record_file.hpp"
#include "ims/error_state_model.hpp"

namespace imscal::ims::zupt_records {

using error_state::kSize;

// What the forward pass keeps per propagation instant k (k = 0: the initial state).
struct Epoch {
  std::size_t last_sample = 0;  // sample index ending the interval (k - 1, k]; unused for k = 0
  double t_s = 0.0;
  ErrorVector correction = ErrorVector::Zero();         // error estimate fed back at k
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();  // estimates after the updates at k
  Eigen::Vector3d acc_bias = Eigen::Vector3d::Zero();
};

// The matrices of instant k, which only the backward pass needs.
struct EpochCovariances {
  ErrorMatrix transition;     // from k - 1 to k
  ErrorMatrix predicted_cov;  // at k before the updates
  ErrorMatrix filtered_cov;   // at k after the updates
};

// The backward pass' result at instant k.
struct SmoothedError {
  // Smoothed error relative to the fed-back (post-update) nominal at k.
  ErrorVector after = ErrorVector::Zero();
  // after + correction[k]: relative to the nominal before the updates at k, i.e. the end of
  // the mechanised interval (k - 1, k].
  ErrorVector before = ErrorVector::Zero();
  ErrorVector variance = ErrorVector::Zero();  // diagonal of the smoothed covariance
};

// The forward pass' Epochs, appended in order. last_sample goes through a double, exact below
// 2^53 samples.
class EpochFile {
 public:
  static constexpr std::size_t kValues = 2 + kSize + 6;
  EpochFile() : file_(kValues, 1024, "the smoother's instants") {}
  void append(const Epoch& e) {
    values_[0] = static_cast<double>(e.last_sample);
    values_[1] = e.t_s;
    std::copy_n(e.correction.data(), kSize, values_.data() + 2);
    std::copy_n(e.gyro_bias.data(), 3, values_.data() + 2 + kSize);
    std::copy_n(e.acc_bias.data(), 3, values_.data() + 5 + kSize);
    file_.append(values_.data());
  }
  Epoch read(std::size_t k) {
    const double* v = file_.record(k);
    Epoch e;
    e.last_sample = static_cast<std::size_t>(v[0]);
    e.t_s = v[1];
    e.correction = Eigen::Map<const ErrorVector>(v + 2);
    e.gyro_bias = Eigen::Map<const Eigen::Vector3d>(v + 2 + kSize);
    e.acc_bias = Eigen::Map<const Eigen::Vector3d>(v + 5 + kSize);
    return e;
  }
  std::size_t size() const { return file_.size(); }

 private:
  RecordFile file_;
  std::array<double, kValues> values_{};
};

// The forward pass' EpochCovariances, one record per instant, written in order and read back
// by the backward pass in reverse. 512 instants per block: 2.8 MB of buffer.
class CovarianceFile {
 public:
  static constexpr std::size_t kValues = 3 * kSize * kSize;
  CovarianceFile() : file_(kValues, 512, "the smoother's covariances") {}
  void append(const EpochCovariances& c) {
    std::copy_n(c.transition.data(), kSize * kSize, values_.data());
    std::copy_n(c.predicted_cov.data(), kSize * kSize, values_.data() + kSize * kSize);
    std::copy_n(c.filtered_cov.data(), kSize * kSize, values_.data() + 2 * kSize * kSize);
    file_.append(values_.data());
  }
  EpochCovariances read(std::size_t k) {
    const double* v = file_.record(k);
    EpochCovariances c;
    c.transition = Eigen::Map<const ErrorMatrix>(v);
    c.predicted_cov = Eigen::Map<const ErrorMatrix>(v + kSize * kSize);
    c.filtered_cov = Eigen::Map<const ErrorMatrix>(v + 2 * kSize * kSize);
    return c;
  }
  std::size_t size() const { return file_.size(); }

 private:
  RecordFile file_;
  std::vector<double> values_ = std::vector<double>(kValues);
};

// The backward pass' SmoothedErrors, appended from the last instant to the first (the order the
// pass gives them) and read by instant.
class SmoothedErrorFile {
 public:
  static constexpr std::size_t kValues = 3 * kSize;
  SmoothedErrorFile() : file_(kValues, 1024, "the smoother's smoothed errors") {}
  void append_before(const SmoothedError& s) {
    std::copy_n(s.after.data(), kSize, values_.data());
    std::copy_n(s.before.data(), kSize, values_.data() + kSize);
    std::copy_n(s.variance.data(), kSize, values_.data() + 2 * kSize);
    file_.append(values_.data());
  }
  SmoothedError read(std::size_t k) {
    const double* v = file_.record(file_.size() - 1 - k);
    SmoothedError s;
    s.after = Eigen::Map<const ErrorVector>(v);
    s.before = Eigen::Map<const ErrorVector>(v + kSize);
    s.variance = Eigen::Map<const ErrorVector>(v + 2 * kSize);
    return s;
  }
  std::size_t size() const { return file_.size(); }

 private:
  RecordFile file_;
  std::array<double, kValues> values_{};
};

}  // namespace imscal::ims::zupt_records
