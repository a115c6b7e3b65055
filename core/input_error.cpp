#include "core/input_error.hpp"

#include <fmt/format.h>

namespace imscal {
namespace {
std::string compose(const std::string& file, std::size_t line, const std::string& field,
                    const std::string& problem) {
  std::string where = file;
  if (line > 0) where += fmt::format(":{}", line);
  if (!field.empty()) where += fmt::format(": field '{}'", field);
  return fmt::format("{}: {}", where, problem);
}
}  // namespace

InputError::InputError(std::string file, std::size_t line, std::string field,
                       const std::string& problem)
    : std::runtime_error(compose(file, line, field, problem)),
      file_(std::move(file)),
      line_(line),
      field_(std::move(field)),
      problem_(problem) {}

}  // namespace imscal
