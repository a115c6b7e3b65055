#include "core/json_output.hpp"

#include <cmath>

#include <spdlog/spdlog.h>

namespace imscal {

std::string json_text(const nlohmann::json& value, int indent, const std::string& target) {
  try {
    return value.dump(indent) + "\n";
  } catch (const nlohmann::json::type_error&) {  // 316: a string is not valid UTF-8
    spdlog::warn(
        "{}: a text taken from an input (a file name or a header line) is not valid UTF-8; its "
        "invalid bytes are written as U+FFFD",
        target);
    return value.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  }
}

nlohmann::json json_number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

}  // namespace imscal
