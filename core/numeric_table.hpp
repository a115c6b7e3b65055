#pragma once
// A numeric CSV table as the robot-side files use it (robot logs, joint errors, poses):
//   # key: value          metadata lines, any number, before the header
//   name_1,name_2,...     one header line with the column names (units in the names)
//   1.5,2.25,...          rows of numbers, as many fields as the header
// The reader checks the structure only (field count, every field a finite number) and keeps the
// line number of every row, so that the format's own checks can name file, line and field.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace imscal {

struct NumericTable {
  std::string file;                                   // as given, for messages
  std::map<std::string, std::string> metadata;        // from the '# key: value' lines
  std::map<std::string, std::size_t> metadata_lines;  // 1-based line of each metadata key
  std::size_t header_line = 0;                        // 1-based
  std::vector<std::string> columns;
  std::vector<double> values;      // row-major, rows() x columns.size()
  std::vector<std::size_t> lines;  // 1-based file line of each row

  std::size_t rows() const { return lines.size(); }
  double at(std::size_t row, std::size_t column) const {
    return values[row * columns.size() + column];
  }
  // Index of a column; InputError naming the header line when it is missing.
  std::size_t column(const std::string& name) const;
  // The metadata value; InputError when it is missing.
  const std::string& meta(const std::string& key) const;
  // The line of a metadata key (0 when it is missing), for messages about its value.
  std::size_t meta_line(const std::string& key) const;
};

// InputError (file, line, field) for: a missing or empty file, no header, a row with a wrong
// number of fields, a field that is not a number or is NaN/Inf, duplicate column names, an
// empty line among the rows. A UTF-8 byte-order mark before the first line is skipped with a
// warning.
NumericTable read_numeric_table(const std::filesystem::path& file);

// The same reading and checks, the rows handed over one at a time instead of kept (a reader
// that converts them holds no second copy of a long file): `header` once, after the header line,
// with the metadata and columns (no rows) and how many lines are left at most (to reserve);
// then `row` with each data row's values, in column order, and its 1-based line.
using NumericHeaderUse = std::function<void(const NumericTable& header, std::size_t lines_left)>;
using NumericRowUse = std::function<void(std::span<const double> values, std::size_t line)>;
void read_numeric_rows(const std::filesystem::path& file, const NumericHeaderUse& header,
                       const NumericRowUse& row);

}  // namespace imscal
