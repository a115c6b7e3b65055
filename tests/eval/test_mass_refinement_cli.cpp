// `imscal identify` with `model.refine_mass_parameters` or `model.refine_gravity` on a record too
// short to refine the mass parameters (32 samples): a clear input error naming the key, nothing
// written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal::eval {
namespace {

namespace fs = std::filesystem;

class MassRefinementCli : public test_support::ScratchDirTest {};

TEST_F(MassRefinementCli, IdentifyRefusesATooShortRecordNamingTheKey) {
  const fs::path source(IMSCAL_SOURCE_DIR);
  for (const std::string key : {"refine_mass_parameters", "refine_gravity"}) {
    std::string text =
        test_support::read_text(source / "datasets/identification/ident-default.yaml");
    const std::string off = key + ": false";
    const std::size_t at = text.find(off);
    ASSERT_NE(at, std::string::npos) << "the shipped config states the key " << key;
    text.replace(at, off.size(), key + ": true");
    const fs::path config = dir_ / "ident.yaml", out = dir_ / "out";
    std::ofstream(config) << text;
    const int status = test_support::run_imscal(
        "identify --joint-errors " + (source / "fuzz/corpus/joint_errors/small.csv").string() +
            " --config " + config.string() + " --robot " +
            (source / "datasets/robots/kr16.yaml").string() + " --out " + out.string(),
        dir_ / "message.log");
    const std::string message = test_support::read_text(dir_ / "message.log");
    EXPECT_EQ(status, 2) << message;
    EXPECT_NE(message.find("field 'model." + key + "'"), std::string::npos) << message;
    EXPECT_NE(message.find("too short"), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(out)) << "nothing is written";
  }
}

}  // namespace
}  // namespace imscal::eval
