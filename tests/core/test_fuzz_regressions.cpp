// Replays every input that fuzzing found troublesome (tests/data/fuzz_regressions/<target>/, one
// folder per fuzz target, see scripts/fuzz.sh) and the seed corpora (fuzz/corpus/<target>/)
// through the same readers as the fuzz targets: each must be accepted or refused with an
// InputError; a crash, a sanitizer report or another exception fails the test (CI runs it under
// ASan and UBSan too).
#include <gtest/gtest.h>

#include <filesystem>

#include "fuzz/fuzz_readers.hpp"

namespace {

namespace fs = std::filesystem;

int replay(const fs::path& root) {
  int replayed = 0;
  if (!fs::is_directory(root)) return 0;
  for (const auto& folder : fs::directory_iterator(root)) {
    if (!folder.is_directory()) continue;
    const std::string target = folder.path().filename().string();
    for (const auto& input : fs::directory_iterator(folder.path())) {
      SCOPED_TRACE(input.path().string());
      EXPECT_NO_THROW(imscal::fuzz::read_with(target, input.path()));
      ++replayed;
    }
  }
  return replayed;
}

TEST(FuzzRegressions, EveryKnownInputIsAcceptedOrRefusedCleanly) {
  const int regressions = replay(fs::path(IMSCAL_TEST_DATA_DIR) / "fuzz_regressions");
  const int seeds = replay(fs::path(IMSCAL_SOURCE_DIR) / "fuzz" / "corpus");
  EXPECT_GE(seeds,
            13);  // at least one seed per target (13 targets): the corpora must not go missing
  std::printf("replayed %d regression inputs and %d seeds\n", regressions, seeds);
}

}  // namespace
