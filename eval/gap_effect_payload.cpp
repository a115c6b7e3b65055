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

namespace imscal::eval {
namespace {

// The unit-payload torque along the drive's actual motion where known (the mass loads the arm as
// it moves), else along q_d.
Column unit_torque(const ShapeContext& x, std::size_t j) {
  const bool internal = j < x.s.unit_payload_internal_nm_kg.size() &&
                        x.s.unit_payload_internal_nm_kg[j].size() == std::size_t(x.n);
  return to_column(internal ? x.s.unit_payload_internal_nm_kg[j] : x.s.unit_payload_nm_kg[j]);
}

// A shape of `width` parameters per loaded joint, its columns `columns_of(j)` on joint j.
template <typename ColumnsOf>
CandidateShape per_joint(const ShapeContext& x, const std::vector<std::size_t>& loaded,
                         std::string label, int width, const ColumnsOf& columns_of,
                         const std::string& stem) {
  CandidateShape sh;
  sh.label = std::move(label);
  sh.columns.assign(x.nj, Eigen::MatrixXd());
  const Eigen::Index p = Eigen::Index(width * int(loaded.size()));
  for (std::size_t i = 0; i < loaded.size(); ++i) {
    const std::size_t j = loaded[i];
    Eigen::MatrixXd c = Eigen::MatrixXd::Zero(x.n, p);
    c.middleCols(Eigen::Index(i) * width, width) = matrix_of(columns_of(j));
    sh.columns[j] = c;
    for (int w = 0; w < width; ++w)
      sh.parameter_names.push_back(
          width == 1 ? fmt::format("dm_over_k_{}_rad_per_kg", x.s.joint_names[j])
                     : fmt::format("{}{}_{}_rad_per_kg", stem, w, x.s.joint_names[j]));
  }
  return sh;
}

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  if (x.joint != 0) return {};  // one candidate for all joints, as the IMS chain's errors
  // Every joint the payload loads (d tau / d m above 1e-6 N m/kg), each with its own
  // parameters: the same mass error acts on each through that joint's own compliance and loop.
  std::vector<std::size_t> loaded;
  for (std::size_t j = 0; j < x.nj; ++j)
    if (rms_of(to_column(x.s.unit_payload_nm_kg[j])) > 1e-6) loaded.push_back(j);
  if (loaded.empty()) return {};
  std::vector<CandidateShape> out;
  out.push_back(per_joint(
      x, loaded, "d tau / d m / k on every loaded joint", 1,
      [&](std::size_t j) { return std::vector<Column>{unit_torque(x, j)}; }, ""));
  for (const auto& [scale, count] : {std::pair{0.03, 4}, std::pair{0.1, 6}}) {
    // Plain copies: clang 14 does not let a lambda capture structured bindings.
    const double tl = scale;
    const int order = count;
    const int ms = int(std::lround(1000.0 * tl));
    out.push_back(per_joint(
        x, loaded,
        fmt::format("d tau / d m through Laguerre {} ms x{} on every loaded joint", ms, order),
        order, [&](std::size_t j) { return laguerre(unit_torque(x, j), tl, order, x.s); },
        fmt::format("laguerre{}ms_", ms)));
  }
  // Both time scales: the loop's fast reaction to the inertia part and its slow one (the PI
  // working off the static part).
  out.push_back(per_joint(
      x, loaded, "d tau / d m through Laguerre 30 ms x4 + 100 ms x6 on every loaded joint", 10,
      [&](std::size_t j) {
        std::vector<Column> cols = laguerre(unit_torque(x, j), 0.03, 4, x.s);
        for (auto& c : laguerre(unit_torque(x, j), 0.1, 6, x.s)) cols.push_back(std::move(c));
        return cols;
      },
      "laguerre30ms100ms_"));
  return out;
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
    .nominal = &kNominal,
};

}  // namespace imscal::eval
