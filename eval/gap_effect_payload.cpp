// Payload mismatch: all joints at once (one mass acts on every joint it loads): per joint
// u_j = d tau_j / d m_payload, [u_j], [L_30ms,0..3 u_j], [L_100ms,0..5 u_j] or
// [L_30ms,0..3 u_j, L_100ms,0..5 u_j] with its own parameters per joint (Δm / k_j through joint
// j's loop). In the nominal model: Δm [kg] of every payload of the path; m + Δm >= 0.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "eval/gap_effect_shapes.hpp"
#include "eval/gap_nominal_plant.hpp"
#include "eval/gap_shape_pool.hpp"

namespace imscal::eval {
namespace {

// The unit-payload torque along the drive's actual motion where known (the mass loads the arm as
// it moves), else along q_d.
Column unit_torque(const ShapeContext& x, std::size_t j) {
  const bool internal = j < x.s.unit_payload_internal_nm_kg.size() &&
                        x.s.unit_payload_internal_nm_kg[j].size() == std::size_t(x.n);
  return to_column(internal ? x.s.unit_payload_internal_nm_kg[j] : x.s.unit_payload_nm_kg[j]);
}

// The pool's columns per loaded joint (eval/gap_shape_pool.hpp): u_j, L_30ms,0..3 u_j,
// L_100ms,0..5 u_j.
constexpr Eigen::Index kPoolWidth = 11;

// A shape of `width` parameters per loaded joint, pool columns from `first` on: joint i of
// `loaded` takes parameters [i width, (i + 1) width).
PooledShape per_joint(const ShapeContext& x, const std::vector<std::size_t>& loaded,
                      std::string label, int width, Eigen::Index first, const std::string& stem) {
  PooledShape sh;
  sh.label = std::move(label);
  sh.pool_columns.assign(x.nj, {});
  sh.first_parameter.assign(x.nj, 0);
  for (std::size_t i = 0; i < loaded.size(); ++i) {
    const std::size_t j = loaded[i];
    sh.first_parameter[j] = Eigen::Index(i) * width;
    for (int w = 0; w < width; ++w) {
      sh.pool_columns[j].push_back(first + w);
      sh.parameter_names.push_back(
          width == 1 ? fmt::format("dm_over_k_{}_rad_per_kg", x.s.joint_names[j])
                     : fmt::format("{}{}_{}_rad_per_kg", stem, w, x.s.joint_names[j]));
    }
  }
  return sh;
}

std::vector<ShapePool> shape_pools(const ShapeContext& x) {
  if (x.joint != 0) return {};  // one candidate for all joints, as the IMS chain's errors
  // Every joint the payload loads (d tau / d m above 1e-6 N m/kg), each with its own
  // parameters: the same mass error acts on each through that joint's own compliance and loop.
  std::vector<std::size_t> loaded;
  for (std::size_t j = 0; j < x.nj; ++j)
    if (rms_of(to_column(x.s.unit_payload_nm_kg[j])) > 1e-6) loaded.push_back(j);
  if (loaded.empty()) return {};
  ShapePool pool;
  pool.columns.assign(x.nj, Eigen::MatrixXd());
  for (std::size_t j : loaded) {
    const Column u = unit_torque(x, j);
    Eigen::MatrixXd m(x.n, kPoolWidth);
    m.col(0) = u;
    laguerre_into(u, 0.03, x.s, m.middleCols(1, 4));
    laguerre_into(u, 0.1, x.s, m.middleCols(5, 6));
    pool.columns[j] = std::move(m);
  }
  pool.shapes.push_back(per_joint(x, loaded, "d tau / d m / k on every loaded joint", 1, 0, ""));
  pool.shapes.push_back(per_joint(x, loaded,
                                  "d tau / d m through Laguerre 30 ms x4 on every loaded joint", 4,
                                  1, "laguerre30ms_"));
  pool.shapes.push_back(per_joint(x, loaded,
                                  "d tau / d m through Laguerre 100 ms x6 on every loaded joint", 6,
                                  5, "laguerre100ms_"));
  // Both time scales: the loop's fast reaction to the inertia part and its slow one (the PI
  // working off the static part).
  pool.shapes.push_back(per_joint(
      x, loaded, "d tau / d m through Laguerre 30 ms x4 + 100 ms x6 on every loaded joint", 10, 1,
      "laguerre30ms100ms_"));
  std::vector<ShapePool> pools;
  pools.push_back(std::move(pool));
  return pools;
}

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  return shapes_from_pools(shape_pools(x));
}

const NominalParameterDefinition kNominal{
    .parameter_count = 1,
    .of_drive = false,
    .applies = [](const NominalPlant&, std::size_t) { return true; },
    .nominal_value =
        [](const NominalPlant& plant, std::size_t) {
          double lightest = std::numeric_limits<double>::infinity();
          for (const auto& p : plant.path.payloads) lightest = std::min(lightest, p.body.mass_kg);
          return lightest;
        },
    .typical_value = [](const NominalPlant&, std::size_t) { return 1.0; },  // 1 kg
    .apply =
        [](const NominalParameter&, const double* p, sim::PlantConfig&,
           sim::DesiredJointPath& path) {
          for (auto& payload : path.payloads)
            payload.body.mass_kg = std::max(0.0, payload.body.mass_kg + p[0]);
        },
    .describe =
        [](const std::string&, const NominalParameter&, const Eigen::VectorXd& p_own,
           double nominal) {
          return fmt::format("payload {:.3g} kg (nominal {:.3g} kg)", nominal + p_own[0], nominal);
        },
};

}  // namespace

const EffectDefinition kPayloadMismatchEffect{
    .kind = EffectKind::kPayloadMismatch,
    .name = "payload_mismatch",
    .acts_through_dynamics = true,
    .what_to_measure = "the path with and without a known extra mass",
    .shapes = shapes,
    .shape_pools = shape_pools,
    .nominal = &kNominal,
};

}  // namespace imscal::eval
