// IMS scale factor, an error of the IMS chain (as eval/gap_effect_kinematic_parameters.cpp): gyro
// scale per flange axis (3), isotropic gyro scale (1), isotropic accelerometer scale (1).
#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  // One candidate for all joints: only joint 0 returns it.
  if (x.joint != 0 || x.s.ims_chain_columns.size() != x.nj) return {};
  std::vector<Eigen::MatrixXd> isotropic;
  for (std::size_t j = 0; j < x.nj; ++j) {
    const auto& c = x.s.ims_chain_columns[j];
    Eigen::MatrixXd m(x.n, 2);
    m << c.gyro_scale.rowwise().sum(), c.accel_scale.col(0);
    isotropic.push_back(m);
  }
  const auto iso = [&](std::size_t j) -> const Eigen::MatrixXd& { return isotropic[j]; };
  const auto gyro = [&](std::size_t j) -> const Eigen::MatrixXd& {
    return x.s.ims_chain_columns[j].gyro_scale;
  };
  return {x.shared("gyro scale, isotropic", iso, {0}, {"gyro_scale"}),
          x.shared("gyro scale per flange axis", gyro, {0, 1, 2},
                   {"gyro_scale_x", "gyro_scale_y", "gyro_scale_z"}),
          x.shared("accelerometer scale, isotropic", iso, {1}, {"accel_scale"})};
}

}  // namespace

const EffectDefinition kImsScaleFactorEffect{
    .kind = EffectKind::kImsScaleFactor,
    .name = "ims_scale_factor",
    .acts_through_dynamics = false,
    .what_to_measure =
        "turn tests of the IMS about each axis by a known angle (rotary table or "
        "joint 6) and a known linear displacement",
    .shapes = shapes,
    .size_in_words = size_of_every_parameter,
};

}  // namespace imscal::eval
