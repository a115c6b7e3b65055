#pragma once
// Small text helpers shared by the CSV readers and writers: trimming, splitting, strict number
// parsing (the whole field must be a number) and the shortest round-trip formatting of doubles.
#include <cstddef>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

namespace imscal::csv {

std::string_view trim(std::string_view text);  // strips spaces, tabs and a trailing '\r'
std::vector<std::string_view> split(std::string_view line, char separator);
// True when the whole (trimmed) field is a number (a leading '+' allowed); NaN/Inf parse too, the
// caller decides whether they are acceptable.
bool parse_number(std::string_view field, double& value);
// Shortest decimal text that reads back to the same double ("0.1", "1e-09").
std::string format_shortest(double value);
void append_shortest(std::string& out, double value);
// How many lines are left in `in` at most (counted from where it stands, then `in` put back
// there), to reserve a reader's rows; 0 when `in` cannot tell its position.
std::size_t lines_left(std::istream& in);

}  // namespace imscal::csv
