#pragma once
// YAML allows a parser to keep either of two equal keys in one map; a config with a second
// `validate:` block would then run with only one of them, silently. This check walks the parse
// events (aliases are not expanded, so it is linear in the text) and refuses the second key.
#include <string>

namespace imscal {

// InputError (origin, line of the repeated key, its key path) for the first map key that appears
// twice in one map of the first document of `text`. Syntax errors are left to the loader.
void refuse_duplicate_yaml_keys(const std::string& text, const std::string& origin);

}  // namespace imscal
