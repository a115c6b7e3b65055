#pragma once
// A YAML config node that knows where it came from, so that every error names the file, the
// line and the key path ("sensor.gyro.bias_rad_s"), and unknown keys are refused, not ignored.
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace imscal {

class ConfigNode {
 public:
  // Parses a YAML file; a syntax error becomes an InputError with the line.
  static ConfigNode load_file(const std::filesystem::path& file);
  // Parses YAML text; `origin` stands for the file name in messages.
  static ConfigNode load_string(const std::string& text, const std::string& origin);

  bool has(std::string_view key) const;
  ConfigNode child(std::string_view key) const;  // required; missing key -> InputError
  std::optional<ConfigNode> optional_child(std::string_view key) const;
  // Refuses any key of this map that is not in `allowed` (typos must not pass silently).
  void require_only_keys(std::initializer_list<std::string_view> allowed) const;

  double as_double() const;  // finite number
  long as_int() const;
  bool as_bool() const;
  std::string as_string() const;
  // A file named by this string: relative paths are relative to the folder of the config file
  // this node was read from. Absolute and normalised; InputError when empty or not a file.
  std::filesystem::path as_existing_file() const;
  std::vector<double> as_doubles() const;  // a sequence of finite numbers
  Eigen::Vector3d as_vector3() const;      // a sequence of exactly 3 finite numbers
  std::vector<ConfigNode> as_sequence() const;
  std::vector<std::string> keys() const;

  // Shorthands: value of a child, or the default when the key is absent.
  double get_double(std::string_view key, double fallback) const;
  long get_int(std::string_view key, long fallback) const;
  bool get_bool(std::string_view key, bool fallback) const;
  std::string get_string(std::string_view key, const std::string& fallback) const;

  bool is_map() const { return node_.IsMap(); }
  bool is_sequence() const { return node_.IsSequence(); }
  std::size_t line() const;  // 1-based line of this node in its file (0 if unknown)
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  const YAML::Node& raw() const { return node_; }

  [[noreturn]] void fail(const std::string& problem) const;  // throws InputError here

 private:
  ConfigNode(YAML::Node node, std::string file, std::string path);
  std::string key_text(const YAML::Node& key) const;
  YAML::Node node_;
  std::string file_;
  std::string path_;
};

}  // namespace imscal
