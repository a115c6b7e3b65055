#pragma once
// The gap diagnosis as a report: JSON (every figure, machine-readable; units in the key names)
// and plain text (the verdict first, then the tables).
#include <nlohmann/json.hpp>
#include <string>

#include "eval/gap_diagnosis.hpp"

namespace imscal::eval {

nlohmann::json diagnosis_json(const GapSignals& signals, const Diagnosis& diagnosis);
std::string diagnosis_text(const GapSignals& signals, const Diagnosis& diagnosis);

}  // namespace imscal::eval
