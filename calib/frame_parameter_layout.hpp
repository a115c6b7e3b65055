#pragma once
// The reported unknowns of the frame-and-bias bundle by name: each optional model declares its
// parameter block when the bundle is set up, and the covariance, the estimates and the weak
// directions look blocks up by that name (e.g. "time_offset"), never by position.
//
// Order: the covariance's rows follow the order of declaration, each block's components in
// turn, named "<block>.<component>" (FrameCalibrationResult::parameter_names).
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "calib/frame_covariance.hpp"

namespace imscal::calib {

class FrameParameterLayout {
 public:
  // A block of `parameters` whose tangent has one entry per component. quaternion: an Eigen
  // quaternion (x, y, z, w) with EigenQuaternionManifold (2 rad per tangent unit; its value is
  // reported as a rotation vector). indices: the parameter entry of each component (a
  // SubsetManifold block that estimates only some of its entries); empty: 0, 1, 2, ...
  void add_quaternion(const std::string& name, double* parameters,
                      std::vector<std::string> components);
  void add(const std::string& name, double* parameters, std::vector<std::string> components,
           std::vector<int> indices = {});

  bool contains(const std::string& block) const;
  // Row of the block's first component in the covariance; throws std::out_of_range.
  int offset(const std::string& block) const;
  // The covariance's row of "<block>.<component>": none if not declared (find), or
  // std::out_of_range (index).
  std::optional<int> find(const std::string& block, const std::string& component) const;
  int index(const std::string& block, const std::string& component) const;

  const std::vector<CovarianceBlock>& covariance_blocks() const { return blocks_; }
  // The estimate of every component, in the covariance's order [SI; rotations: rotation vector,
  // rad].
  Eigen::VectorXd values() const;

 private:
  std::vector<CovarianceBlock> blocks_;
  std::vector<std::vector<int>> indices_;  // per block; empty for quaternions
  std::vector<int> offsets_;
};

}  // namespace imscal::calib
