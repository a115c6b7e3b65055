#pragma once
// A reader's refusal of a bad file, as the bad-input tests check it: the reader throws an
// InputError that names the file and the field at fault (the project's rule for bad input).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/input_error.hpp"
#include "tests/support/text_file.hpp"

namespace imscal::test_support {

// Writes `text` as the whole of `file`, calls `read(file)` and checks that it refuses the file
// with an InputError naming `file` and `field`; a read that returns fails the test ("accepted").
template <class Reader>
void expect_refused_naming_field(const Reader& read, const std::filesystem::path& file,
                                 const std::string& text, const std::string& field) {
  write_text(file, text);
  try {
    read(file);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file.string());
    EXPECT_EQ(e.field(), field) << e.what();
  }
}

}  // namespace imscal::test_support
