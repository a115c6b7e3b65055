#pragma once
// JSON read from a user's file. nlohmann keeps the last of two equal keys in one object without a
// word; a hand-edited table with a joint's key given twice would then use one of them silently,
// so the reader refuses it, naming the line of the second one.
#include <nlohmann/json.hpp>
#include <string>

namespace imscal {

// The parsed document. InputError (origin, line) on a syntax error or a number beyond double;
// InputError (origin, line, key) when a key appears twice in one object.
nlohmann::json parse_json_refusing_duplicate_keys(const std::string& text,
                                                  const std::string& origin);

}  // namespace imscal
