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
  std::printf("replayed %d regression inputs and %d seeds\n", regressions, seeds);
}

// Every fuzz target (fuzz/fuzz_<target>.cpp) has a seed corpus with at least one input, so that
// its reader is replayed here; 19 targets: the corpora must not go missing.
TEST(FuzzRegressions, EveryTargetHasSeeds) {
  const fs::path fuzz = fs::path(IMSCAL_SOURCE_DIR) / "fuzz";
  int targets = 0;
  for (const auto& source : fs::directory_iterator(fuzz)) {
    const std::string name = source.path().stem().string();
    if (name.rfind("fuzz_", 0) != 0 || source.path().extension() != ".cpp") continue;
    ++targets;
    const fs::path corpus = fuzz / "corpus" / name.substr(5);
    SCOPED_TRACE(corpus.string());
    ASSERT_TRUE(fs::is_directory(corpus));
    EXPECT_FALSE(fs::is_empty(corpus));
  }
  EXPECT_GE(targets, 19);
}

}  // namespace
