#pragma once
// Existence checks for paths that come from user input (configs, command lines). The throwing
// std::filesystem overloads raise filesystem_error on e.g. a name longer than NAME_MAX; for a
// reader such a path simply does not name a file, so these never throw.
#include <filesystem>
#include <system_error>

namespace imscal {

inline bool is_existing_file(const std::filesystem::path& path) noexcept {
  std::error_code error;
  return std::filesystem::is_regular_file(path, error);
}

inline bool path_exists(const std::filesystem::path& path) noexcept {
  std::error_code error;
  return std::filesystem::exists(path, error);
}

inline bool is_existing_folder(const std::filesystem::path& path) noexcept {
  std::error_code error;
  return std::filesystem::is_directory(path, error);
}

}  // namespace imscal
