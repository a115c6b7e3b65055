#include "core/json_fields.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "core/json_input.hpp"

namespace imscal {

using nlohmann::json;

namespace {

const char* type_name(const json& value) {
  return value.is_null() ? "null" : value.type_name();
}

// A value as a short text for messages: long arrays or objects would drown the message.
std::string shown(const json& value) {
  std::string text = value.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

}  // namespace

JsonField::JsonField(const std::string* file, const json* value, std::string path)
    : file_(file), value_(value), path_(std::move(path)) {}

void JsonField::refuse(const std::string& why) const {
  throw InputError(*file_, 0, path_, why);
}

JsonField JsonField::operator[](const std::string& key) const {
  const std::string child = path_.empty() ? key : path_ + "." + key;
  if (!value_->is_object()) refuse(fmt::format("not an object but {}", type_name(*value_)));
  const auto found = value_->find(key);
  if (found == value_->end()) throw InputError(*file_, 0, child, "missing");
  return JsonField(file_, &*found, child);
}

JsonField JsonField::operator[](std::size_t index) const {
  if (!value_->is_array()) refuse(fmt::format("not a list but {}", type_name(*value_)));
  if (index >= value_->size())
    refuse(fmt::format("has {} items, item {} is missing", value_->size(), index));
  return JsonField(file_, &(*value_)[index], fmt::format("{}[{}]", path_, index));
}

std::optional<JsonField> JsonField::optional(const std::string& key) const {
  if (!value_->is_object()) refuse(fmt::format("not an object but {}", type_name(*value_)));
  const auto found = value_->find(key);
  if (found == value_->end() || found->is_null()) return std::nullopt;
  return JsonField(file_, &*found, path_.empty() ? key : path_ + "." + key);
}

std::size_t JsonField::size() const {
  if (!value_->is_array()) refuse(fmt::format("not a list but {}", type_name(*value_)));
  return value_->size();
}

double JsonField::number() const {
  if (!value_->is_number())
    refuse(value_->is_null() ? std::string("not a finite number (null: NaN or missing)")
                             : "not a number: " + shown(*value_));
  const double v = value_->get<double>();
  if (!std::isfinite(v)) refuse("not a finite number");
  return v;
}

double JsonField::number_or_nan() const {
  return value_->is_null() ? std::numeric_limits<double>::quiet_NaN() : number();
}

long long JsonField::integer() const {
  if (value_->is_number_unsigned()) {
    const auto v = value_->get<unsigned long long>();
    if (v > static_cast<unsigned long long>(std::numeric_limits<long long>::max()))
      refuse("integer out of range: " + shown(*value_));
    return static_cast<long long>(v);
  }
  if (!value_->is_number_integer()) refuse("not an integer: " + shown(*value_));
  return value_->get<long long>();
}

std::size_t JsonField::count() const {
  const long long v = integer();
  if (v < 0) refuse(fmt::format("negative: {}", v));
  return static_cast<std::size_t>(v);
}

bool JsonField::boolean() const {
  if (!value_->is_boolean()) refuse("not true or false: " + shown(*value_));
  return value_->get<bool>();
}

std::string JsonField::text() const {
  if (!value_->is_string()) refuse("not a text: " + shown(*value_));
  return value_->get<std::string>();
}

std::vector<double> JsonField::numbers() const {
  std::vector<double> out(size());
  for (std::size_t k = 0; k < out.size(); ++k) out[k] = (*this)[k].number();
  return out;
}

std::vector<double> JsonField::numbers_or_nan() const {
  std::vector<double> out(size());
  for (std::size_t k = 0; k < out.size(); ++k) out[k] = (*this)[k].number_or_nan();
  return out;
}

std::vector<std::string> JsonField::texts() const {
  std::vector<std::string> out(size());
  for (std::size_t k = 0; k < out.size(); ++k) out[k] = (*this)[k].text();
  return out;
}

void JsonDocument::check_version(const std::string& key, long long version,
                                 const std::string& what) const {
  if (!root_.is_object() || !root_.contains(key))
    throw InputError(file_, 0, key, fmt::format("not {} (no '{}' version key)", what, key));
  const json& given = root_[key];
  if (!given.is_number_integer() || given.get<long long>() != version)
    throw InputError(file_, 0, key,
                     fmt::format("unknown format version {} (this imscal reads version {})",
                                 shown(given), version));
}

JsonDocument read_json_document(const std::filesystem::path& file) {
  const std::string text = read_input_file(file);
  return JsonDocument(file.string(), parse_json_refusing_duplicate_keys(text, file.string()));
}

}  // namespace imscal
