#pragma once
// The file readers take paths: each fuzz input is written to one scratch file per process (in
// /tmp, named after the target and the pid) and the reader is pointed at it.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace imscal::fuzz {

inline std::filesystem::path write_input(const char* target, const char* extension,
                                         const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() /
      (std::string("imscal-fuzz-") + target + "-" + std::to_string(::getpid()) + extension);
  std::FILE* out = std::fopen(file.c_str(), "wb");
  if (out == nullptr) __builtin_trap();  // the harness itself is broken: stop loudly
  if (size > 0 && std::fwrite(data, 1, size, out) != size) __builtin_trap();
  std::fclose(out);
  return file;
}

}  // namespace imscal::fuzz
