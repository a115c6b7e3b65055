// The JSON reader every imscal JSON input goes through: whatever nlohmann refuses comes back as an
// InputError naming the file and, for a syntax error, its line. Truth: the hand-written documents
// below, whose faulty line is known by construction.
#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "core/json_input.hpp"

namespace {

using imscal::InputError;
using imscal::parse_json_refusing_duplicate_keys;

InputError refusal_of(const std::string& text) {
  try {
    parse_json_refusing_duplicate_keys(text, "t.json");
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "accepted: " << text;
  return InputError("", 0, "", "");
}

TEST(JsonInput, SyntaxErrorNamesFileAndLine) {
  const InputError e = refusal_of("{\n  \"a\": 1,\n  \"b\": ]\n}");
  EXPECT_EQ(e.file(), "t.json");
  EXPECT_EQ(e.line(), 3u);  // the stray ']' is on line 3
}

TEST(JsonInput, NumberBeyondDoubleIsAnInputErrorNotACrash) {
  // 1e710 overflows double: nlohmann throws out_of_range, not parse_error.
  const InputError e = refusal_of("{\"imscal-frames\": 1e710}");
  EXPECT_EQ(e.file(), "t.json");
  EXPECT_NE(std::string(e.what()).find("not valid JSON"), std::string::npos) << e.what();
}

TEST(JsonInput, RepeatedKeyNamesItsSecondLine) {
  const InputError e = refusal_of("{\n \"k\": 1,\n \"k\": 2\n}");
  EXPECT_EQ(e.line(), 3u);
  EXPECT_EQ(e.field(), "k");
}

TEST(JsonInput, ValidDocumentIsParsed) {
  EXPECT_EQ(parse_json_refusing_duplicate_keys("{\"x\": [1, 2.5]}", "t.json")["x"][1], 2.5);
}

}  // namespace
