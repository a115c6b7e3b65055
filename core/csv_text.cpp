#include "core/csv_text.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <system_error>

namespace imscal::csv {

std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r");
  return text.substr(first, last - first + 1);
}

std::vector<std::string_view> split(std::string_view line, char separator) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = line.find(separator, start);
    fields.push_back(line.substr(start, end == std::string_view::npos ? end : end - start));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return fields;
}

bool parse_number(std::string_view field, double& value) {
  field = trim(field);
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  if (field.empty()) return false;
  const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  return ec == std::errc() && ptr == field.data() + field.size();
}

void append_shortest(std::string& out, double value) {
  char buffer[32];
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, ec == std::errc() ? ptr : buffer);
}

std::string format_shortest(double value) {
  std::string text;
  append_shortest(text, value);
  return text;
}

std::size_t lines_left(std::istream& in) {
  const std::istream::pos_type here = in.tellg();
  if (here == std::istream::pos_type(-1)) return 0;
  std::size_t lines = 1;
  std::array<char, 1 << 16> buffer{};
  while (in.read(buffer.data(), std::streamsize(buffer.size())) || in.gcount() > 0)
    lines += std::size_t(std::count(buffer.data(), buffer.data() + in.gcount(), '\n'));
  in.clear();
  in.seekg(here);
  return lines;
}

}  // namespace imscal::csv
