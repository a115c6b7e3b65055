#pragma once
// SHA-256 (FIPS 180-4) of bytes and of files, as 64 lower-case hex digits: the checksums a run
// folder records for every stage input and output, so that an unchanged input can be recognised
// and a run audited.
#include <filesystem>
#include <string>
#include <string_view>

namespace imscal {

std::string sha256_hex(std::string_view bytes);
// Throws InputError(file, 0, "", ...) when the file cannot be read.
std::string sha256_hex_of_file(const std::filesystem::path& file);

}  // namespace imscal
