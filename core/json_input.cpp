#include "core/json_input.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "core/input_error.hpp"

namespace imscal {
namespace {

using json = nlohmann::json;

struct RepeatedKey {
  std::string key;
  std::size_t occurrence = 0;  // 1-based, among all keys of the document with this text
};

// The 1-based line of the n-th `"key"` written as an object key (followed by ':'), or 0 when the
// key is written with escapes and cannot be found as plain text.
std::size_t line_of_key(const std::string& text, const RepeatedKey& repeated) {
  const std::string quoted = "\"" + repeated.key + "\"";
  std::size_t seen = 0;
  for (std::size_t at = text.find(quoted); at != std::string::npos;
       at = text.find(quoted, at + 1)) {
    const std::size_t after = text.find_first_not_of(" \t\r\n", at + quoted.size());
    if (after == std::string::npos || text[after] != ':') continue;
    if (++seen == repeated.occurrence) {
      return 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + long(at), '\n'));
    }
  }
  return 0;
}

// The 1-based line holding the 1-based byte position nlohmann reports for a syntax error.
std::size_t line_of_byte(const std::string& text, std::size_t byte) {
  const auto end = text.begin() + long(std::min(byte, text.size()));
  return 1 + static_cast<std::size_t>(std::count(text.begin(), end, '\n'));
}

}  // namespace

json parse_json_refusing_duplicate_keys(const std::string& text, const std::string& origin) {
  std::vector<std::set<std::string>> open_objects;
  std::map<std::string, std::size_t> key_counts;
  std::optional<RepeatedKey> repeated;
  const json::parser_callback_t watch = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) open_objects.emplace_back();
    if (event == json::parse_event_t::object_end && !open_objects.empty()) open_objects.pop_back();
    if (event == json::parse_event_t::key && !open_objects.empty()) {
      const std::string key = parsed.get<std::string>();
      const std::size_t occurrence = ++key_counts[key];
      if (!open_objects.back().insert(key).second && !repeated)
        repeated = RepeatedKey{key, occurrence};
    }
    return true;
  };
  json root;
  try {
    root = json::parse(text, watch);
  } catch (const json::parse_error& e) {
    throw InputError(origin, line_of_byte(text, e.byte), "",
                     fmt::format("not valid JSON: {}", e.what()));
  } catch (const json::exception& e) {  // numbers beyond double (1e710) are out_of_range
    throw InputError(origin, 0, "", fmt::format("not valid JSON: {}", e.what()));
  }
  if (repeated) {
    throw InputError(
        origin, line_of_key(text, *repeated), repeated->key,
        fmt::format("key '{}' appears twice in one object; only one may be given", repeated->key));
  }
  return root;
}

}  // namespace imscal
