#pragma once
// The one way to open an input file. Only a regular file is read: a named pipe would block the
// reader forever, a directory or a device gives a meaningless stream error, so they are refused
// at once with an InputError naming the file and what it is. A file that cannot be opened or read
// is refused with the operating system's reason (strerror).
#include <filesystem>
#include <fstream>
#include <istream>
#include <string>
#include <string_view>

namespace imscal {

// A read-only descriptor of a regular file (O_CLOEXEC, blocking); the caller closes it.
// InputError when the path is missing, unreadable, or not a regular file.
int open_regular_file(const std::filesystem::path& file);

// The file as a stream; InputError as open_regular_file.
std::ifstream open_input_stream(const std::filesystem::path& file);

// The whole file as bytes; InputError as open_regular_file, or on a read error.
std::string read_input_file(const std::filesystem::path& file);

// InputError naming `file` and the system's reason when the stream hit a read error (badbit).
void throw_if_read_failed(const std::istream& in, const std::filesystem::path& file);

// The UTF-8 byte-order mark some editors write at the start of a text file.
inline constexpr std::string_view kUtf8ByteOrderMark = "\xEF\xBB\xBF";

// Removes a leading UTF-8 byte-order mark from `first_line`; true when there was one.
bool strip_byte_order_mark(std::string& first_line);

}  // namespace imscal
