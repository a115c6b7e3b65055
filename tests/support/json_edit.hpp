#pragma once
// A JSON document with one value changed or removed: how the bad-input tests of the JSON readers
// make their cases from a good document.
#include <nlohmann/json.hpp>

namespace imscal::test_support {

// Stands for "no value": edited(document, at, kRemovedJson) removes the member at `at`.
inline const nlohmann::json kRemovedJson(nlohmann::json::value_t::discarded);

// `document` with the value at `at` replaced by `value` (added where absent), or removed when
// `value` is kRemovedJson.
inline nlohmann::json edited(nlohmann::json document, const nlohmann::json::json_pointer& at,
                             const nlohmann::json& value) {
  if (value.is_discarded())
    document[at.parent_pointer()].erase(at.back());
  else
    document[at] = value;
  return document;
}

}  // namespace imscal::test_support
