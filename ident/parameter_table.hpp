#pragma once
// The identified error model of a robot, as exported to parameters.json / parameters.csv and
// loaded by the precontrol: per joint, the operating-point cell grid, the ARX model of every cell
// (paper, equation 2 and Table 2), the backlash l of equation 3, and how well each model fits.
// Every cell of the grid has a model: cells that could not be identified are filled from the
// nearest identified cell, and say so (status "filled", filled_from, reason).
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "ident/arx_model.hpp"
#include "ident/exogenous_inputs.hpp"
#include "ident/operating_point.hpp"

namespace imscal::ident {

// Version 2 added model_form, preview_cycles, the further inputs (extra_inputs,
// direction_speed_scale_rad_s; per cell nx and c); version 1 tables are read as single-input
// forward models without preview. Version 3 added the transmission-error inputs and the joints'
// transmission_error_rad_per_rad and transmission_error_compliance_rad_per_nm (version 2 tables
// are read with 0 for both). Version 4 added the second transmission-error harmonic (inputs
// transmission_error_2_sin / _cos, the joints' transmission_error_2_rad_per_rad). Version 5
// added the model torque's link masses refined from the identification data (model_torque_links,
// optional). Version 6 added the joints' gear mode the transmission error passes through
// (transmission_error_gear_mode, optional: natural frequency and damping ratio), which filtered
// the plain pairs. Version 7 added the gear-mode pairs as inputs of their own
// (transmission_error_mode_sin / _cos, transmission_error_2_mode_sin / _cos), beside the plain
// pairs or instead of them, and the mode acts on those only; a version 6 table with a gear mode
// is read as version 7 with its pairs as the gear-mode kinds (the same values).
inline constexpr int kParameterTableSchemaVersion = 7;

// What the cells' models are (ident/joint_identification.hpp): forward error models of the
// loop (paper, eq. 2: the predicted error Δq̂ from q_d), or inverse models (the offset that makes
// the link follow q_d), which the precontrol must be fed P = preview_cycles ahead:
// x(k) = q_d(k + P). The precontrol's arithmetic is the same for both.
enum class TableForm { kForward, kInverse };
const char* to_string(TableForm form);

// The further inputs of the cells' models (TableInput, their names and values):
// ident/exogenous_inputs.hpp.

enum class CellStatus {
  kIdentified,  // fitted from this cell's own rows
  kFilled,      // copied from the cell `filled_from` (reason says why)
  kNeutral,     // pass-through, zero correction: the joint could not be identified (reason)
};
const char* to_string(CellStatus status);

struct CellFitFigures {
  std::size_t estimation_rows = 0;
  std::size_t validation_rows = 0;
  double one_step_fit_percent = 0.0;  // NRMSE fit on held-out data (NaN: no held-out data)
  double simulation_fit_percent = 0.0;
  // NRMSE fit of the free-run joint error Δq̂ against Δq = q_d - q_m: the same misfit as
  // simulation_fit_percent, but relative to the spread of the joint error instead of the joint
  // angle (which is ~100 % for any model that follows the command).
  double joint_error_fit_percent = 0.0;
  double residual_rms_rad = 0.0;
  bool whiteness_passed = false;
  bool input_residual_passed = false;
  double spectral_radius = 0.0;

  friend bool operator==(const CellFitFigures&, const CellFitFigures&) = default;
};

struct CellParameters {
  std::vector<int> bands;  // band index per dimension of the joint's grid
  CellStatus status = CellStatus::kIdentified;
  int filled_from = -1;  // flat index of the source cell when filled
  std::string reason;    // why filled (empty when identified)
  ArxStructure structure;
  std::vector<double> a;  // a_1..a_na
  std::vector<double> b;  // b_0..b_{nb-1}
  std::vector<double> c;  // further inputs' coefficients, input after input (nx each)
  CellFitFigures figures;

  ArxModel model(double sample_time_s) const;
  friend bool operator==(const CellParameters&, const CellParameters&) = default;
};

struct JointParameters {
  std::string name;
  std::vector<CellDimension> dimensions;  // grid of this joint (SI bounds)
  double backlash_l_rad = 0.0;            // paper's l_i: error +l moving +, -l moving -
  double backlash_l_sigma_rad = 0.0;
  bool backlash_identified = false;
  std::size_t backlash_lag_samples = 0;  // lag used for the direction of motion
  // Scale of the torque-sign input [N m] (> 0 when the table has that input, else 0).
  double torque_sign_scale_nm = 0.0;
  // Phase of the gear's transmission error per rad of joint angle [rad/rad]: harmonic per motor
  // revolution x gear ratio (> 0 when the table has the transmission-error inputs, else 0).
  double transmission_error_rad_per_rad = 0.0;
  // The second harmonic's phase rate [rad/rad] (> 0 when the table has the second
  // transmission-error inputs, else 0).
  double transmission_error_2_rad_per_rad = 0.0;
  // The gear's compliance 1 / k [rad/(N m)]: the error's phase is f (x + compliance x model
  // torque), the motor angle the deflected gear sits at (0: the joint angle alone).
  double transmission_error_compliance_rad_per_nm = 0.0;
  // The locked-motor gear mode the transmission error passes through to the link
  // (ident/exogenous_inputs.hpp): natural frequency [rad/s] and damping ratio; 0: none (the
  // plain sin/cos pair, every table before version 6).
  double transmission_error_mode_rad_s = 0.0;
  double transmission_error_mode_damping = 0.0;
  // The largest joint error |q_d - q| and its largest rate (over 8 ms) in the identification
  // data [rad, rad/s]: what the models were identified on. The precontrol's supervisor derives
  // its default tolerances from them (ident/precontrol.hpp). 0: not known (version 1 tables).
  double offset_envelope_rad = 0.0;
  double offset_rate_envelope_rad_s = 0.0;
  std::vector<CellParameters> cells;  // flat (row-major) order of the grid

  CellGrid grid() const { return CellGrid(dimensions); }
  friend bool operator==(const JointParameters& x, const JointParameters& y) {
    if (x.dimensions.size() != y.dimensions.size()) return false;
    for (std::size_t d = 0; d < x.dimensions.size(); ++d)
      if (x.dimensions[d].quantity != y.dimensions[d].quantity ||
          x.dimensions[d].bounds != y.dimensions[d].bounds)
        return false;
    return x.name == y.name && x.backlash_l_rad == y.backlash_l_rad &&
           x.backlash_l_sigma_rad == y.backlash_l_sigma_rad &&
           x.backlash_identified == y.backlash_identified &&
           x.backlash_lag_samples == y.backlash_lag_samples &&
           x.torque_sign_scale_nm == y.torque_sign_scale_nm &&
           x.transmission_error_rad_per_rad == y.transmission_error_rad_per_rad &&
           x.transmission_error_2_rad_per_rad == y.transmission_error_2_rad_per_rad &&
           x.transmission_error_compliance_rad_per_nm ==
               y.transmission_error_compliance_rad_per_nm &&
           x.transmission_error_mode_rad_s == y.transmission_error_mode_rad_s &&
           x.transmission_error_mode_damping == y.transmission_error_mode_damping &&
           x.offset_envelope_rad == y.offset_envelope_rad &&
           x.offset_rate_envelope_rad_s == y.offset_rate_envelope_rad_s && x.cells == y.cells;
  }
};

struct DataSource {
  std::string file;    // as given on the command line
  std::string sha256;  // of the file's bytes
  std::size_t samples = 0;
  std::string description;  // the file's "# source:" header

  friend bool operator==(const DataSource&, const DataSource&) = default;
};

// One link of the model torque's rigid-body model as the identification data refined it
// (eval/mass_refinement.hpp): the robot file's (nominal) mass [kg] and centre of mass [m, in the
// link's frame], the estimate with its 1σ, and whether the table's models were identified with
// the estimate (`refined`) or with the nominal values; held_out_z is the held-out test's score.
struct LinkMassParameters {
  bool refined = false;
  double held_out_z = 0.0;
  double nominal_mass_kg = 0.0, mass_kg = 0.0, mass_sigma_kg = 0.0;
  std::array<double, 3> nominal_com_m{}, com_m{}, com_sigma_m{};

  friend bool operator==(const LinkMassParameters&, const LinkMassParameters&) = default;
};

struct ParameterTable {
  int schema_version = kParameterTableSchemaVersion;
  std::string robot;
  double sample_time_s = 0.002;
  std::string created_by;  // "imscal <version>"
  TableForm model_form = TableForm::kForward;
  int preview_cycles = 0;  // the precontrol's input leads q_d by this many cycles (inverse form)
  std::vector<TableInput> extra_inputs;       // every cell's further inputs, in order
  double direction_speed_scale_rad_s = 0.01;  // of the direction input [rad/s]
  DataSource source;
  std::vector<JointParameters> joints;
  // The model torque's links, base to tool, when the identification refined them (its users
  // compute the torque with the refined links' values); empty: the robot file's values.
  std::vector<LinkMassParameters> model_torque_links;

  friend bool operator==(const ParameterTable&, const ParameterTable&) = default;
};

}  // namespace imscal::ident
