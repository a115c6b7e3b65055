#pragma once
// The one error type for input the tool cannot use. It names the file, the line and the field
// and says what was expected, so that a user can find and fix the offending value.
#include <cstddef>
#include <stdexcept>
#include <string>

namespace imscal {

class InputError : public std::runtime_error {
 public:
  // line: 1-based line number in the file; 0 when the problem concerns the whole file.
  // field: column or key name ("gyro_x_rad", "sensor.accelerometer.bias"); empty if none.
  InputError(std::string file, std::size_t line, std::string field, const std::string& problem);

  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }
  const std::string& field() const { return field_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string file_;
  std::size_t line_;
  std::string field_;
  std::string problem_;
};

}  // namespace imscal
