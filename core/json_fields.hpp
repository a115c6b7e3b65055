#pragma once
// Typed access to a JSON document read from a file, for the readers of imscal's own result files
// (run.json, mounting_report.json, identification_report.json): each value is taken through a
// JsonField that knows its path in the document ("joints[2].cells[0].label"), so that a missing
// or mistyped value is refused with an InputError naming the file and that path.
#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace imscal {

class JsonField {
 public:
  JsonField(const std::string* file, const nlohmann::json* value, std::string path);

  // The member `key` of this object; refused when this is no object or has no such member.
  JsonField operator[](const std::string& key) const;
  // The item `index` of this array; refused when this is no array or is shorter.
  JsonField operator[](std::size_t index) const;
  // The member `key`, or nullopt when it is absent or null; refused when this is no object.
  std::optional<JsonField> optional(const std::string& key) const;

  bool is_null() const { return value_->is_null(); }
  std::size_t size() const;      // of an array; refused otherwise
  double number() const;         // finite
  double number_or_nan() const;  // null (how imscal writes NaN) gives NaN
  long long integer() const;
  std::size_t count() const;  // a non-negative integer
  bool boolean() const;
  std::string text() const;
  std::vector<double> numbers() const;         // an array of finite numbers
  std::vector<double> numbers_or_nan() const;  // an array of numbers or nulls (NaN)
  std::vector<std::string> texts() const;

  const std::string& path() const { return path_; }
  const nlohmann::json& value() const { return *value_; }
  [[noreturn]] void refuse(const std::string& why) const;

 private:
  const std::string* file_;
  const nlohmann::json* value_;
  std::string path_;
};

// A parsed document and the file it came from; its fields refer to it (keep it alive).
class JsonDocument {
 public:
  JsonDocument(std::string file, nlohmann::json root)
      : file_(std::move(file)), root_(std::move(root)) {}
  JsonDocument(const JsonDocument&) = delete;
  JsonDocument& operator=(const JsonDocument&) = delete;

  JsonField root() const { return JsonField(&file_, &root_, ""); }
  const std::string& file() const { return file_; }

  // Refuses a document that is no object or whose `key` is not the integer `version` (an
  // imscal file of another kind or format version), naming `what` the file should be.
  void check_version(const std::string& key, long long version, const std::string& what) const;

 private:
  std::string file_;
  nlohmann::json root_;
};

// Reads and parses `file` (core/input_file.hpp, core/json_input.hpp): InputError for a file that
// is not a readable regular file, not JSON, or repeats a key in one object.
JsonDocument read_json_document(const std::filesystem::path& file);

}  // namespace imscal
