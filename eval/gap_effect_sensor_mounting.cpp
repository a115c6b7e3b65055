// Sensor mounting, an error of the IMS chain (as eval/gap_effect_kinematic_parameters.cpp): the
// mounting twist of the sensor on the flange: rotation (3), translation (3) or both (6).
#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  // One candidate for all joints: only joint 0 returns it.
  if (x.joint != 0 || x.s.ims_chain_columns.size() != x.nj) return {};
  const auto m = [&](std::size_t j) -> const Eigen::MatrixXd& {
    return x.s.ims_chain_columns[j].mounting;
  };
  return {x.shared("mounting rotation", m, {3, 4, 5}, {"rx_rad", "ry_rad", "rz_rad"}),
          x.shared("mounting translation", m, {0, 1, 2}, {"tx_m", "ty_m", "tz_m"}),
          x.shared("mounting rotation and translation", m, {3, 4, 5, 0, 1, 2},
                   {"rx_rad", "ry_rad", "rz_rad", "tx_m", "ty_m", "tz_m"})};
}

}  // namespace

const EffectDefinition kSensorMountingEffect{
    .kind = EffectKind::kSensorMounting,
    .name = "sensor_mounting",
    .acts_through_dynamics = false,
    .what_to_measure =
        "the frame calibration's rest poses again with larger wrist rotations (the "
        "mounting error grows with the rotation away from the first pose)",
    .shapes = shapes,
    .size_in_words = size_of_every_parameter,
};

}  // namespace imscal::eval
