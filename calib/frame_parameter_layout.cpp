#include "calib/frame_parameter_layout.hpp"

#include <Eigen/Geometry>
#include <numeric>
#include <stdexcept>

#include "ims/so3.hpp"

namespace imscal::calib {

void FrameParameterLayout::add_quaternion(const std::string& name, double* parameters,
                                          std::vector<std::string> components) {
  const int next = blocks_.empty() ? 0 : offsets_.back() + blocks_.back().tangent_size;
  blocks_.push_back({name, parameters, 3, 2.0, std::move(components)});
  indices_.emplace_back();
  offsets_.push_back(next);
}

void FrameParameterLayout::add(const std::string& name, double* parameters,
                               std::vector<std::string> components, std::vector<int> indices) {
  if (indices.empty()) {
    indices.resize(components.size());
    std::iota(indices.begin(), indices.end(), 0);
  }
  const int next = blocks_.empty() ? 0 : offsets_.back() + blocks_.back().tangent_size;
  const int size = static_cast<int>(components.size());
  blocks_.push_back({name, parameters, size, 1.0, std::move(components)});
  indices_.push_back(std::move(indices));
  offsets_.push_back(next);
}

bool FrameParameterLayout::contains(const std::string& block) const {
  for (const CovarianceBlock& b : blocks_)
    if (b.name == block) return true;
  return false;
}

int FrameParameterLayout::offset(const std::string& block) const {
  for (std::size_t i = 0; i < blocks_.size(); ++i)
    if (blocks_[i].name == block) return offsets_[i];
  throw std::out_of_range("frame calibration: no parameter block " + block);
}

std::optional<int> FrameParameterLayout::find(const std::string& block,
                                              const std::string& component) const {
  for (std::size_t i = 0; i < blocks_.size(); ++i) {
    if (blocks_[i].name != block) continue;
    const std::vector<std::string>& c = blocks_[i].components;
    for (std::size_t k = 0; k < c.size(); ++k)
      if (c[k] == component) return offsets_[i] + static_cast<int>(k);
  }
  return std::nullopt;
}

int FrameParameterLayout::index(const std::string& block, const std::string& component) const {
  const std::optional<int> row = find(block, component);
  if (!row) throw std::out_of_range("frame calibration: no parameter " + block + "." + component);
  return *row;
}

Eigen::VectorXd FrameParameterLayout::values() const {
  const int size = blocks_.empty() ? 0 : offsets_.back() + blocks_.back().tangent_size;
  Eigen::VectorXd out(size);
  for (std::size_t i = 0; i < blocks_.size(); ++i) {
    const CovarianceBlock& b = blocks_[i];
    if (indices_[i].empty()) {
      const Eigen::Quaterniond q(Eigen::Map<const Eigen::Quaterniond>(b.parameters));
      out.segment<3>(offsets_[i]) = ims::quat_log<double>(q);
      continue;
    }
    for (int k = 0; k < b.tangent_size; ++k)
      out[offsets_[i] + k] = b.parameters[indices_[i][static_cast<std::size_t>(k)]];
  }
  return out;
}

}  // namespace imscal::calib
