#pragma once
// JSON text for an output file. Strings that come from input files or file names may hold bytes
// that are not UTF-8 (a Latin-1 '#source:' line, a file name in a legacy encoding); JSON must be
// UTF-8, so such bytes are written as U+FFFD with a warning, instead of failing the whole command
// after its work is done.
#include <nlohmann/json.hpp>
#include <string>

namespace imscal {

// value.dump(indent) and a final newline; invalid UTF-8 replaced (and warned about, naming
// `target`, the file the text is for).
std::string json_text(const nlohmann::json& value, int indent, const std::string& target);

// v, or null when v is NaN or infinite (JSON has no such numbers; readers take null as NaN,
// `JsonField::number_or_nan`).
nlohmann::json json_number_or_null(double v);

}  // namespace imscal
