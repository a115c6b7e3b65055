#include "tools/report_structure_section.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <vector>

#include "core/units.hpp"
#include "tools/report_gnuplot.hpp"

namespace imscal::tools {
namespace {

std::string number(double value) {
  return std::isfinite(value) ? fmt::format("{:.3g}", value) : "n/a";
}

// "value ± σ" in the unit `scale` converts to.
std::string with_sigma(const ident::StructureEstimate& e, double scale) {
  if (!e.identified()) return "n/a";
  return number(e.value * scale) + " &plusmn; " + number(e.sigma * scale);
}

std::string structure_row(const std::string& joint, const ident::IdentifiedStructure& s) {
  constexpr double kMicro = 1e6, kKilo = 1e-3;
  return fmt::format(
      "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>"
      "<td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
      html_escape(joint), s.cells, with_sigma(s.compliance_rad_per_nm, kMicro),
      number(s.nominal_compliance_rad_per_nm * kMicro), with_sigma(s.stiffness_nm_per_rad, kKilo),
      with_sigma(s.direction_offset_rad, kArcsecPerRad),
      number(s.transmission_error_harmonic_per_motor_rev),
      with_sigma(s.transmission_error_amplitude_rad, kArcsecPerRad),
      with_sigma(s.transmission_error_phase_rad, kDegPerRad),
      number(s.transmission_error_joint_speed_rad_s * kDegPerRad),
      number(s.transmission_error_frequency_hz));
}

std::string vector_text(const std::array<double, 3>& v, double scale) {
  return number(v[0] * scale) + " " + number(v[1] * scale) + " " + number(v[2] * scale);
}

std::string link_row(std::size_t link, const ident::LinkMassParameters& l) {
  constexpr double kCm = 100.0;
  return fmt::format(
      "<tr><td>{}</td><td>{}</td><td>{:.2f}</td><td>{} &plusmn; {}</td><td>{}</td>"
      "<td>{} &plusmn; {}</td><td>{}</td></tr>\n",
      link + 1, l.refined ? "refined" : "nominal kept", l.held_out_z, number(l.mass_kg),
      number(l.mass_sigma_kg), number(l.nominal_mass_kg), vector_text(l.com_m, kCm),
      vector_text(l.com_sigma_m, kCm), vector_text(l.nominal_com_m, kCm));
}

// "value ± σ (robot file's)" of a level, or the robot file's alone where not estimated.
std::string level_cell(const ident::FrictionLevel& level, bool estimated) {
  if (!estimated) return fmt::format("n/a ({})", number(level.nominal));
  return fmt::format("{} &plusmn; {} ({})", number(level.value), number(level.sigma),
                     number(level.nominal));
}

std::string friction_row(const ident::ReportedFrictionLevels& r) {
  const ident::JointFrictionLevels& l = r.levels;
  return fmt::format(
      "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
      html_escape(r.name), level_cell(l.coulomb_nm, l.estimated),
      level_cell(l.viscous_nm_s_per_rad, l.estimated),
      level_cell(l.reflected_inertia_kg_m2, l.estimated), number(l.torque_fit_percent),
      l.dead_time_cycles, l.estimated ? "" : html_escape(l.not_estimated));
}

}  // namespace

std::string friction_levels_html(const std::vector<ident::ReportedFrictionLevels>& levels) {
  if (levels.empty()) return "";
  std::string rows;
  for (const ident::ReportedFrictionLevels& r : levels) rows += friction_row(r);
  return "<p>The drives' friction levels and reflected motor inertia from the motor encoders' "
         "following error against the nominal model torque (ident/friction_levels.hpp), with "
         "1&sigma; (statistical only: the balance's model error, see its fit, biases them by "
         "more) beside the robot file's in brackets.</p>\n"
         "<table>\n<tr><th>joint</th><th>Coulomb [N m]</th><th>viscous [N m s/rad]</th>"
         "<th>reflected inertia [kg m&sup2;]</th><th>balance fit [%]</th>"
         "<th>dead time [cycles]</th><th>not estimated</th></tr>\n" +
         rows + "</table>\n";
}

std::string model_torque_links_html(const std::vector<ident::LinkMassParameters>& links) {
  if (links.empty()) return "";
  std::string rows;
  for (std::size_t i = 0; i < links.size(); ++i) rows += link_row(i, links[i]);
  return "<p>The model torque's link masses and centres of mass (in the link's frame) estimated "
         "from the identification data (eval/mass_refinement.hpp), with 1&sigma; beside the robot "
         "file's. Where the links are used (refined), the table's models were identified with "
         "the estimates and its users compute the model torque with them: the identification "
         "keeps them only where the tables they give fit the held-out rows better (BIC); z is "
         "each link's held-out score on the refinement's own drive model.</p>\n"
         "<table>\n<tr><th>link</th><th>used</th><th>held-out z</th><th>mass [kg]</th>"
         "<th>robot file's [kg]</th><th>centre of mass [cm]</th><th>robot file's [cm]</th>"
         "</tr>\n" +
         rows + "</table>\n";
}

std::string structure_table_html(const ident::IdentificationReport& report) {
  std::string rows;
  for (const ident::ReportedJoint& j : report.joints)
    if (j.structure) rows += structure_row(j.name, *j.structure);
  if (rows.empty()) return "";
  return "<p>The drive structure the identified models imply (ident/identified_structure.hpp), "
         "with 1&sigma; beside the values the identification config gave: the compliance is the "
         "joint error per N m of model torque (the gear's and the position loop's), the direction "
         "offset what the direction of motion adds as the speed tends to zero (both static "
         "gains), the transmission error the amplitude and phase at the link of the harmonic the "
         "identification used (the order search's where it ran, else the config's) at the "
         "frequency the data hold it: the models' response at the joint speed "
         "and error frequency given (the cells' rms speeds, weighted as the cells are).</p>\n"
         "<table>\n<tr><th>joint</th><th>cells</th><th>compliance [&micro;rad/(N m)]</th>"
         "<th>config's 1/k [&micro;rad/(N m)]</th><th>stiffness [kN m/rad]</th>"
         "<th>direction offset [&Prime;]</th>"
         "<th>transmission error harmonic [per motor rev]</th><th>amplitude [&Prime;]</th>"
         "<th>phase [&deg;]</th><th>at joint speed [&deg;/s]</th><th>error frequency [Hz]</th>"
         "</tr>\n" +
         rows + "</table>\n";
}

}  // namespace imscal::tools
