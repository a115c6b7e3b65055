#include "eval/population_row.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "core/input_error.hpp"
#include "ident/identification_report.hpp"

namespace imscal::eval {

namespace fs = std::filesystem;

namespace {

std::string number(double value) {
  return fmt::format("{:.6g}", value);
}

}  // namespace

const std::vector<std::string>& population_figure_columns() {
  static const std::vector<std::string> figures{"te_found_order_A1",
                                                "te_found_order_A2",
                                                "te_found_order_A3",
                                                "te_found_order_A4",
                                                "te_found_order_A5",
                                                "te_found_order_A6",
                                                "seed_line_before_mm",
                                                "seed_line_after_mm",
                                                "seed_line_reduction_percent",
                                                "seed_line_true_reduction_percent",
                                                "seed_line_scatter_floor_mm",
                                                "seed_line_systematic_mm",
                                                "iso100_systematic_mm",
                                                "iso100_before_mm",
                                                "iso100_after_mm",
                                                "iso100_reduction_percent",
                                                "iso100_true_reduction_percent",
                                                "iso100_scatter_floor_mm"};
  return figures;
}

std::vector<double> found_orders(const fs::path& identify_dir) {
  const fs::path file = identify_dir / "identification_report.json";
  const ident::IdentificationReport report = ident::read_identification_report(file);
  if (!report.header.order_search)
    throw InputError(file.string(), 0, "transmission_error_order_search",
                     "missing: identify ran without --search-transmission-error-order");
  std::vector<double> orders;
  for (const ident::OrderSearchJoint& joint : report.header.order_search->joints)
    orders.push_back(joint.chosen_harmonic_per_motor_rev);
  return orders;
}

std::pair<std::string, std::string> plant_row(const sim::PlantDraw& plant,
                                              const std::vector<double>& orders,
                                              const VerifiedFigures& line,
                                              const VerifiedFigures& iso) {
  std::string header = "seed", row = std::to_string(plant.seed);
  const auto add = [&](const std::string& name, double value) {
    header.append(",").append(name);
    row.append(",").append(number(value));
  };
  for (int i = 0; i < calib::kJointCount; ++i) {
    const sim::JointDraw& j = plant.joints[i];
    const std::string a = fmt::format("A{}", i + 1);
    double te_arcsec = 0.0, main_order = 0.0, main_amplitude = 0.0;
    for (const auto& o : j.transmission_error) {
      te_arcsec += o.amplitude_arcsec;
      if (o.amplitude_arcsec > main_amplitude)
        main_amplitude = o.amplitude_arcsec, main_order = o.harmonic_per_motor_rev;
    }
    add("link_mass_" + a, j.link_mass);
    add("com_offset_mm_" + a,
        std::hypot(j.centre_of_mass_offset_mm[0], j.centre_of_mass_offset_mm[1],
                   j.centre_of_mass_offset_mm[2]));
    add("gear_stiffness_" + a, j.gear_stiffness);
    add("coulomb_" + a, j.coulomb_friction);
    add("viscous_" + a, j.viscous_friction);
    add("play_arcmin_" + a, j.play_arcmin);
    add("te_orders_" + a, static_cast<double>(j.transmission_error.size()));
    add("te_sum_arcsec_" + a, te_arcsec);
    add("te_main_order_" + a, main_order);
    add("position_gain_" + a, j.position_gain);
    add("velocity_gain_" + a, j.velocity_gain);
  }
  add("dead_time_cycles", plant.dead_time_cycles);
  add("payload_mass", plant.payload_mass);
  for (std::size_t j = 0; j < orders.size(); ++j)
    add(fmt::format("te_found_order_A{}", j + 1), orders[j]);
  for (const auto& [prefix, f] : {std::pair<const char*, const VerifiedFigures&>{"seed_line", line},
                                  std::pair<const char*, const VerifiedFigures&>{"iso100", iso}}) {
    add(fmt::format("{}_before_mm", prefix), f.before_mm);
    add(fmt::format("{}_after_mm", prefix), f.after_mm);
    add(fmt::format("{}_reduction_percent", prefix), f.reduction_percent);
    add(fmt::format("{}_true_reduction_percent", prefix), f.true_reduction_percent);
    add(fmt::format("{}_scatter_floor_mm", prefix), f.scatter_floor_mm);
    add(fmt::format("{}_systematic_mm", prefix), f.systematic_mm);
  }
  return {header, row};
}

PopulationTable read_population_rows(std::uint64_t first_seed, std::uint64_t last_seed,
                                     const fs::path& out, std::string& csv) {
  PopulationTable table;
  for (std::uint64_t seed = first_seed; seed <= last_seed; ++seed) {
    std::ifstream in(out / fmt::format("plant-{}", seed) / "row.csv");
    std::string header, row;
    if (!std::getline(in, header) || !std::getline(in, row)) continue;
    if (!csv.empty() && header + "\n" != csv.substr(0, csv.find('\n') + 1)) {
      spdlog::warn("population: plant {}'s row has other columns (an older imscal); left out",
                   seed);
      continue;
    }
    if (table.columns.empty()) {
      std::stringstream names(header);
      for (std::string name; std::getline(names, name, ',');) table.columns.push_back(name);
      csv = header + "\n";
    }
    std::stringstream values(row);
    std::vector<double> parsed;
    for (std::string value; std::getline(values, value, ',');) parsed.push_back(std::stod(value));
    table.rows.push_back(parsed);
    csv += row + "\n";
  }
  return table;
}

}  // namespace imscal::eval
