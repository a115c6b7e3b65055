#pragma once
// Frames as imscal writes them in JSON (calibrate's frames.json, the simulator's
// truth/frames.json): {"quaternion_wxyz": [w, x, y, z], ...}.
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

namespace imscal::test_support {

// The rotation of a frame entry, normalised.
inline Eigen::Quaterniond quaternion_of(const nlohmann::json& frame) {
  const auto& q = frame.at("quaternion_wxyz");
  return Eigen::Quaterniond(q.at(0).get<double>(), q.at(1).get<double>(), q.at(2).get<double>(),
                            q.at(3).get<double>())
      .normalized();
}

}  // namespace imscal::test_support
