#include "core/config_node.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "core/path_checks.hpp"
#include "core/yaml_duplicate_keys.hpp"

namespace imscal {

ConfigNode::ConfigNode(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

ConfigNode ConfigNode::load_file(const std::filesystem::path& file) {
  std::string text = read_input_file(file);
  if (text.starts_with(kUtf8ByteOrderMark)) {
    text.erase(0, kUtf8ByteOrderMark.size());
    spdlog::warn("{}: a UTF-8 byte-order mark at the start was skipped", file.string());
  }
  return load_string(text, file.string());
}

ConfigNode ConfigNode::load_string(const std::string& text, const std::string& origin) {
  refuse_duplicate_yaml_keys(text, origin);
  try {
    YAML::Node root = YAML::Load(text);
    if (!root || root.IsNull()) throw InputError(origin, 0, "", "empty YAML document");
    return ConfigNode(root, origin, "");
  } catch (const YAML::Exception& e) {
    throw InputError(origin, static_cast<std::size_t>(e.mark.line + 1), "",
                     "YAML syntax error: " + e.msg);
  }
}

std::size_t ConfigNode::line() const {
  const auto mark = node_.Mark();
  return mark.line >= 0 ? static_cast<std::size_t>(mark.line + 1) : 0;
}

void ConfigNode::fail(const std::string& problem) const {
  throw InputError(file_, line(), path_, problem);
}

bool ConfigNode::has(std::string_view key) const {
  return node_.IsMap() && node_[std::string(key)].IsDefined();
}

std::optional<ConfigNode> ConfigNode::optional_child(std::string_view key) const {
  if (!node_.IsMap()) fail("expected a map of keys");
  YAML::Node c = node_[std::string(key)];
  if (!c.IsDefined()) return std::nullopt;
  const std::string sub = path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  return ConfigNode(c, file_, sub);
}

ConfigNode ConfigNode::child(std::string_view key) const {
  auto c = optional_child(key);
  if (!c) {
    const std::string sub = path_.empty() ? std::string(key) : path_ + "." + std::string(key);
    throw InputError(file_, line(), sub, "required key is missing");
  }
  return *c;
}

// A map key as text; keys that are not plain scalars (YAML allows `? [a, b]: 1`) are refused.
std::string ConfigNode::key_text(const YAML::Node& key) const {
  if (!key.IsScalar()) {
    const auto mark = key.Mark();
    throw InputError(file_, mark.line >= 0 ? static_cast<std::size_t>(mark.line + 1) : 0, path_,
                     "a key must be a plain name, not a list or map");
  }
  return key.Scalar();
}

void ConfigNode::require_only_keys(std::initializer_list<std::string_view> allowed) const {
  if (!node_.IsMap()) fail("expected a map of keys");
  for (const auto& kv : node_) {
    const std::string key = key_text(kv.first);
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string list;
      for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      const std::string sub = path_.empty() ? key : path_ + "." + key;
      const auto mark = kv.first.Mark();
      throw InputError(file_, mark.line >= 0 ? static_cast<std::size_t>(mark.line + 1) : 0, sub,
                       fmt::format("unknown key (allowed here: {})", list));
    }
  }
}

double ConfigNode::as_double() const {
  if (!node_.IsScalar()) fail("expected a number");
  double value = 0.0;
  if (!YAML::convert<double>::decode(node_, value)) {
    fail(fmt::format("expected a number, got '{}'", node_.Scalar()));
  }
  if (!std::isfinite(value)) fail("expected a finite number");
  return value;
}

long ConfigNode::as_int() const {
  if (!node_.IsScalar()) fail("expected an integer");
  long value = 0;
  if (!YAML::convert<long>::decode(node_, value)) {
    fail(fmt::format("expected an integer, got '{}'", node_.Scalar()));
  }
  return value;
}

bool ConfigNode::as_bool() const {
  if (!node_.IsScalar()) fail("expected true or false");
  bool value = false;
  if (!YAML::convert<bool>::decode(node_, value)) {
    fail(fmt::format("expected true or false, got '{}'", node_.Scalar()));
  }
  return value;
}

std::string ConfigNode::as_string() const {
  if (!node_.IsScalar()) fail("expected a string");
  return node_.Scalar();
}

std::filesystem::path ConfigNode::as_existing_file() const {
  const std::string text = as_string();
  if (text.empty()) fail("an empty path");
  const std::filesystem::path given = std::filesystem::path(file_).parent_path() / text;
  std::error_code error;  // a path the OS refuses (e.g. too long) is "not a file" below
  std::filesystem::path path = std::filesystem::absolute(given, error);
  path = (error ? given : path).lexically_normal();
  if (!is_existing_file(path)) fail(fmt::format("'{}' is not a file", path.string()));
  return path;
}

std::vector<ConfigNode> ConfigNode::as_sequence() const {
  if (!node_.IsSequence()) fail("expected a sequence");
  std::vector<ConfigNode> out;
  for (std::size_t i = 0; i < node_.size(); ++i) {
    out.push_back(ConfigNode(node_[i], file_, fmt::format("{}[{}]", path_, i)));
  }
  return out;
}

std::vector<double> ConfigNode::as_doubles() const {
  std::vector<double> out;
  for (const auto& c : as_sequence()) out.push_back(c.as_double());
  return out;
}

Eigen::Vector3d ConfigNode::as_vector3() const {
  const auto v = as_doubles();
  if (v.size() != 3) fail(fmt::format("expected 3 numbers, got {}", v.size()));
  return {v[0], v[1], v[2]};
}

std::vector<std::string> ConfigNode::keys() const {
  if (!node_.IsMap()) fail("expected a map of keys");
  std::vector<std::string> out;
  for (const auto& kv : node_) out.push_back(key_text(kv.first));
  return out;
}

double ConfigNode::get_double(std::string_view key, double fallback) const {
  auto c = optional_child(key);
  return c ? c->as_double() : fallback;
}
long ConfigNode::get_int(std::string_view key, long fallback) const {
  auto c = optional_child(key);
  return c ? c->as_int() : fallback;
}
bool ConfigNode::get_bool(std::string_view key, bool fallback) const {
  auto c = optional_child(key);
  return c ? c->as_bool() : fallback;
}
std::string ConfigNode::get_string(std::string_view key, const std::string& fallback) const {
  auto c = optional_child(key);
  return c ? c->as_string() : fallback;
}

}  // namespace imscal
