#pragma once
// What a run did with one named stage, for the run-stage tests.
#include <gtest/gtest.h>

#include <string>

#include "core/run_stage.hpp"

namespace imscal::test_support {

// The stage's outcome in `summary`; a test failure (and kNotRun) when no stage has that name.
inline StageRun::What stage_outcome(const RunSummary& summary, const std::string& name) {
  for (const auto& stage : summary.stages)
    if (stage.name == name) return stage.what;
  ADD_FAILURE() << name << " not in the summary";
  return StageRun::What::kNotRun;
}

}  // namespace imscal::test_support
