#include "core/numeric_table.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include "core/csv_text.hpp"
#include "core/input_error.hpp"
#include "core/input_file.hpp"

namespace imscal {

std::size_t NumericTable::column(const std::string& name) const {
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (columns[c] == name) return c;
  }
  throw InputError(file, header_line, name, "missing column '" + name + "'");
}

const std::string& NumericTable::meta(const std::string& key) const {
  const auto it = metadata.find(key);
  if (it == metadata.end()) {
    throw InputError(file, 0, key, "missing header line '# " + key + ": ...'");
  }
  return it->second;
}

std::size_t NumericTable::meta_line(const std::string& key) const {
  const auto it = metadata_lines.find(key);
  return it == metadata_lines.end() ? 0 : it->second;
}

namespace {

// The metadata line `text` ('#' first) into the table, if it holds a key.
void add_metadata(std::string_view text, std::size_t line_number, NumericTable& table) {
  const std::string_view body = csv::trim(text.substr(1));
  const auto colon = body.find(':');
  if (colon == std::string_view::npos) return;
  const std::string key(csv::trim(body.substr(0, colon)));
  table.metadata[key] = std::string(csv::trim(body.substr(colon + 1)));
  table.metadata_lines[key] = line_number;
}

void read_header_line(std::string_view text, std::size_t line_number, NumericTable& table) {
  std::set<std::string> seen;
  for (const std::string_view name : csv::split(text, ',')) {
    std::string column(csv::trim(name));
    if (column.empty() || !seen.insert(column).second) {
      throw InputError(table.file, line_number, column,
                       column.empty() ? "empty column name in the header"
                                      : "column '" + column + "' appears twice");
    }
    table.columns.push_back(std::move(column));
  }
  table.header_line = line_number;
}

// The numbers of data line `text` into `values` (as many as the header has columns).
void read_data_line(std::string_view text, std::size_t line_number, const NumericTable& table,
                    std::vector<double>& values) {
  const std::vector<std::string_view> fields = csv::split(text, ',');
  if (fields.size() != table.columns.size()) {
    const bool semicolons = fields.size() == 1 && text.find(';') != std::string_view::npos;
    throw InputError(
        table.file, line_number, "",
        fmt::format("{} fields, the header has {}{}", fields.size(), table.columns.size(),
                    semicolons ? " (';' is not a separator here: use ',')" : ""));
  }
  values.resize(fields.size());
  for (std::size_t c = 0; c < fields.size(); ++c) {
    double& value = values[c];
    if (!csv::parse_number(fields[c], value)) {
      throw InputError(table.file, line_number, table.columns[c],
                       fmt::format("'{}' is not a number", csv::trim(fields[c])));
    }
    if (!std::isfinite(value)) {
      throw InputError(table.file, line_number, table.columns[c],
                       fmt::format("'{}' is not a finite number", csv::trim(fields[c])));
    }
  }
}

}  // namespace

void read_numeric_rows(const std::filesystem::path& path, const NumericHeaderUse& header,
                       const NumericRowUse& row) {
  NumericTable table;
  table.file = path.string();
  std::ifstream in = open_input_stream(path);
  std::string line;
  std::size_t line_number = 0, rows = 0;
  std::vector<double> values;
  while (std::getline(in, line)) {
    ++line_number;
    if (line_number == 1 && strip_byte_order_mark(line))
      spdlog::warn("{}: a UTF-8 byte-order mark at the start was skipped", table.file);
    const std::string_view text = csv::trim(line);
    if (text.empty()) {
      if (table.columns.empty()) continue;
      throw InputError(table.file, line_number, "", "empty line among the data rows");
    }
    if (table.columns.empty()) {
      if (text.front() == '#') {
        add_metadata(text, line_number, table);
        continue;
      }
      read_header_line(text, line_number, table);
      if (header) header(table, csv::lines_left(in));
      continue;
    }
    read_data_line(text, line_number, table, values);
    ++rows;
    if (row) row(values, line_number);
  }
  throw_if_read_failed(in, path);
  if (table.columns.empty()) {
    throw InputError(table.file, line_number, "",
                     line_number == 0 ? "the file is empty" : "no header line with column names");
  }
  if (rows == 0) {
    throw InputError(table.file, table.header_line, "", "no data rows after the header");
  }
}

NumericTable read_numeric_table(const std::filesystem::path& path) {
  NumericTable table;
  read_numeric_rows(
      path,
      [&](const NumericTable& header, std::size_t lines) {
        table = header;
        table.values.reserve(lines * table.columns.size());
        table.lines.reserve(lines);
      },
      [&](std::span<const double> values, std::size_t line) {
        table.values.insert(table.values.end(), values.begin(), values.end());
        table.lines.push_back(line);
      });
  return table;
}

}  // namespace imscal
