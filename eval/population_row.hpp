#pragma once
// A plant's row of a population study (`imscal population`): OUT/plant-SEED/row.csv, a header
// line and one row of its draws (per joint, then the whole robot's), the transmission error's
// order identify found per joint and the figures of its two verifications (datasets/FORMAT.md).
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "eval/population_summary.hpp"
#include "eval/verification_files.hpp"
#include "sim/plant_population.hpp"

namespace imscal::eval {

// The row's outcomes (not draws): left out of the correlations.
const std::vector<std::string>& population_figure_columns();

// (header, row) of a plant: its draws, the orders identify found and both paths' figures.
std::pair<std::string, std::string> plant_row(const sim::PlantDraw& plant,
                                              const std::vector<double>& orders,
                                              const VerifiedFigures& line,
                                              const VerifiedFigures& iso);

// The transmission error's order per motor revolution identify chose per joint, from its
// identification_report.json in `identify_dir`; InputError when it ran without the search.
std::vector<double> found_orders(const std::filesystem::path& identify_dir);

// The finished plants' rows of seeds first..last under `out` (OUT/plant-SEED/row.csv) as one
// table; `csv` gets the same as text (header and rows). A row with other columns than the first
// (an older imscal) is left out with a warning.
PopulationTable read_population_rows(std::uint64_t first_seed, std::uint64_t last_seed,
                                     const std::filesystem::path& out, std::string& csv);

}  // namespace imscal::eval
