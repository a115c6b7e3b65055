#pragma once
// A headline figure of a test, recorded in its XML report (--gtest_output=xml:FILE, which the
// headline tests get from tests/CMakeLists.txt) beside the assertion that holds it: the results
// page (scripts/results.py, docs/results.md) is generated from these, never typed by hand.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>

namespace imscal::test_support {

// `name` says what and in which unit (`seed_line_reduction_measured_percent`); four significant
// digits are more than any of these figures is repeatable to.
inline void record_figure(const std::string& name, double value) {
  ::testing::Test::RecordProperty(name, fmt::format("{:.4g}", value));
}

}  // namespace imscal::test_support
