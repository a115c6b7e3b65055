#pragma once
// A whole file as a string, and a string as a whole file: how the tests read what a run wrote and
// write the inputs they make. Bytes as they are (binary mode): "\r\n" and a missing last newline
// stay visible to the test. A file that cannot be read or written fails the running test with its
// path (a non-fatal failure, so that the test's own check and message still show); the read then
// gives "".
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace imscal::test_support {

// The whole file's bytes; "" and a test failure naming `file` when it cannot be opened.
inline std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    ADD_FAILURE() << "cannot read " << file.string();
    return "";
  }
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Writes `text` as the whole of `file` (replacing it); a test failure naming `file` when it
// cannot be written.
inline void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) ADD_FAILURE() << "cannot write " << file.string();
}

}  // namespace imscal::test_support
