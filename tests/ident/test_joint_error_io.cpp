// joint_errors.csv: exact round trip, gaps split into segments, and every kind of bad input
// refused with the file, the line and the field.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "ident/joint_error_io.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace {
namespace ident = imscal::ident;

class JointErrorFiles : public imscal::test_support::ScratchDirTest {
 protected:
  std::filesystem::path write(const std::string& text) {
    const auto file = dir_ / "joint_errors.csv";
    std::ofstream(file) << text;
    return file;
  }
  // Expects an InputError on `line` (0: any) naming `field` and containing `message`.
  void expect_refused(const std::string& text, std::size_t line, const std::string& field,
                      const std::string& message) {
    const auto file = write(text);
    try {
      ident::read_joint_errors_csv(file);
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const imscal::InputError& e) {
      EXPECT_EQ(e.file(), file.string());
      if (line != 0) {
        EXPECT_EQ(e.line(), line) << e.what();
      }
      EXPECT_EQ(e.field(), field) << e.what();
      EXPECT_NE(e.problem().find(message), std::string::npos) << e.what();
    }
  }
};

const std::string kHeader =
    "# imscal-joint-errors: 1\n# robot: kr16\n# cycle_s: 0.002\n"
    "t_s,payload_kg,q_desired_A1_rad,q_desired_A2_rad,q_measured_A1_rad,q_measured_A2_rad,"
    "q_internal_A1_rad,q_internal_A2_rad\n";

ident::JointErrorLog random_log() {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> normal(0.0, 1.0);
  ident::JointErrorLog log;
  log.robot = "kr16";
  log.cycle_s = 0.002;
  log.source = "imscal calibrate (test)";
  log.metadata = {{"scenario", "identification"}};
  log.joint_names = {"A1", "A2", "A3"};
  log.q_desired_rad.resize(3);
  log.q_measured_rad.resize(3);
  log.q_internal_rad.resize(3);
  for (std::size_t k = 0; k < 500; ++k) {
    // A gap after sample 299 (3 cycles): two segments.
    log.time_s.push_back(0.002 * double(k) + (k >= 300 ? 0.004 : 0.0) + 1e-13 * normal(rng));
    log.payload_kg.push_back(5.0);
    for (std::size_t j = 0; j < 3; ++j) {
      log.q_desired_rad[j].push_back(normal(rng));
      // Joint errors of a robot: about 1e-3 rad (the reader refuses beyond 0.5 rad).
      log.q_measured_rad[j].push_back(log.q_desired_rad[j].back() + normal(rng) * 1e-3);
      log.q_internal_rad[j].push_back(std::ldexp(normal(rng), -40));
    }
  }
  return log;
}

TEST_F(JointErrorFiles, RoundTripIsExactAndGapsSplitSegments) {
  const ident::JointErrorLog log = random_log();
  const auto file = dir_ / "out.csv";
  ident::write_joint_errors_csv(file, log);
  const ident::JointErrorLog back = ident::read_joint_errors_csv(file);
  EXPECT_EQ(back.robot, log.robot);
  EXPECT_EQ(back.cycle_s, log.cycle_s);
  EXPECT_EQ(back.source, log.source);
  EXPECT_EQ(back.metadata, log.metadata);
  EXPECT_EQ(back.joint_names, log.joint_names);
  // 17 significant digits: every double comes back bit for bit.
  EXPECT_EQ(back.time_s, log.time_s);
  EXPECT_EQ(back.payload_kg, log.payload_kg);
  EXPECT_EQ(back.q_desired_rad, log.q_desired_rad);
  EXPECT_EQ(back.q_measured_rad, log.q_measured_rad);
  EXPECT_EQ(back.q_internal_rad, log.q_internal_rad);
  ASSERT_EQ(back.segment_starts, (std::vector<std::size_t>{0, 300}));
  EXPECT_EQ(back.segments().back(), (std::pair<std::size_t, std::size_t>{300, 500}));
  EXPECT_EQ(back.first_data_line, 7u);  // 5 header comments + the column line
}

// A robot with one position sensor per joint: no q_internal block. Written without it, read back
// with the same other columns, bit for bit, and the same as the file with the block.
TEST_F(JointErrorFiles, TheInternalBlockIsOptional) {
  const ident::JointErrorLog with = random_log();
  ident::JointErrorLog without = with;
  without.q_internal_rad.clear();
  ident::write_joint_errors_csv(dir_ / "with.csv", with);
  ident::write_joint_errors_csv(dir_ / "without.csv", without);
  const ident::JointErrorLog back_with = ident::read_joint_errors_csv(dir_ / "with.csv");
  const ident::JointErrorLog back = ident::read_joint_errors_csv(dir_ / "without.csv");
  EXPECT_TRUE(back_with.has_q_internal());
  EXPECT_FALSE(back.has_q_internal());
  EXPECT_TRUE(back.q_internal_rad.empty());
  EXPECT_EQ(back.time_s, back_with.time_s);
  EXPECT_EQ(back.payload_kg, back_with.payload_kg);
  EXPECT_EQ(back.q_desired_rad, back_with.q_desired_rad);
  EXPECT_EQ(back.q_measured_rad, back_with.q_measured_rad);
  EXPECT_EQ(back.segment_starts, back_with.segment_starts);
  EXPECT_EQ(back.sample_lines, back_with.sample_lines);
  // The column line ends with the last q_measured column.
  std::ifstream in(dir_ / "without.csv");
  std::string line, columns;
  while (std::getline(in, line))
    if (line.starts_with("t_s,")) columns = line;
  EXPECT_TRUE(columns.ends_with(",q_measured_A3_rad")) << columns;
  // A row with the internal block's cells on a header without it: too many columns.
  const std::string header = kHeader.substr(0, kHeader.find(",q_internal_A1_rad")) + "\n";
  EXPECT_NO_THROW(ident::read_joint_errors_csv(write(header + "0,5,0.1,0.2,0.1,0.2\n")));
  expect_refused(header + "0,5,0.1,0.2,0.1,0.2,0.1,0.2\n", 5, "", "more than the 6 columns");
}

TEST_F(JointErrorFiles, WriterRefusesToOverwriteWhenAsked) {
  const ident::JointErrorLog log = random_log();
  ident::write_joint_errors_csv(dir_ / "a.csv", log);
  EXPECT_THROW(ident::write_joint_errors_csv(dir_ / "a.csv", log, imscal::Overwrite::kRefuse),
               std::runtime_error);
}

TEST_F(JointErrorFiles, BadInputsRefused) {
  const std::string row = "0,5,0.1,0.2,0.1,0.2,0.1,0.2\n";
  expect_refused("# robot: kr16\n# cycle_s: 0.002\nt_s\n", 1, "imscal-joint-errors",
                 "header line '# imscal-joint-errors: 1' is missing");
  expect_refused("# imscal-joint-errors: 7\n", 1, "imscal-joint-errors", "unknown format version");
  expect_refused("# imscal-joint-errors: 1\n# cycle_s: 0.002\nt_s\n", 1, "robot", "missing");
  expect_refused("# imscal-joint-errors: 1\n# robot: r\n# cycle_s: -1\n", 3, "cycle_s",
                 "positive cycle time");
  expect_refused("# imscal-joint-errors: 1\n# robot: r\n# robot: s\n", 3, "robot", "given twice");
  // Header: a measured column renamed, a missing internal column.
  std::string bad_header = kHeader;
  bad_header.replace(bad_header.find("q_measured_A2_rad"), 17, "q_measured_A2_deg");
  expect_refused(bad_header + row, 4, "q_measured_A2_deg", "expected 'q_measured_A2_rad'");
  std::string short_header = kHeader.substr(0, kHeader.rfind(",q_internal_A2_rad")) + "\n";
  expect_refused(short_header + row, 4, "q_internal_A2_rad", "column missing");
  expect_refused(kHeader + row + "0.002,5,0.1,abc,0.1,0.2,0.1,0.2\n", 6, "q_desired_A2_rad",
                 "'abc' is not a number");
  expect_refused(kHeader + row + "0.002,5,0.1,0.2,nan,0.2,0.1,0.2\n", 6, "q_measured_A1_rad",
                 "not finite");
  expect_refused(kHeader + row + "0.002,5,0.1,0.2,0.1,0.2,0.1\n", 6, "q_internal_A2_rad",
                 "7 columns, the header has 8");
  expect_refused(kHeader + row + "0.002,5,0.1,0.2,0.1,0.2,0.1,0.2,9\n", 6, "",
                 "more than the 8 columns");
  expect_refused(kHeader + row + "0,5,0.1,0.2,0.1,0.2,0.1,0.2\n", 6, "t_s", "does not increase");
  // Corrupted but finite samples, as real controller logs hold: refused with line and column
  // instead of becoming the table's offset envelope or turning the joint neutral.
  expect_refused(kHeader + row + "0.002,5,0.1,0.2,253,0.2,0.1,0.2\n", 6, "q_measured_A1_rad",
                 "a corrupted sample");
  expect_refused(kHeader + row + "0.002,5,0.1,1e282,0.1,0.2,0.1,0.2\n", 6, "q_measured_A2_rad",
                 "a corrupted sample");
  // Jitter: a step of 0.4 cycles (the robot log's rule, so compensate refuses the same log).
  expect_refused(kHeader + row + "0.0008,5,0.1,0.2,0.1,0.2,0.1,0.2\n", 6, "t_s",
                 "less than half the cycle");
  expect_refused(kHeader + row + "0.002,-1,0.1,0.2,0.1,0.2,0.1,0.2\n", 6, "payload_kg",
                 "negative payload");
  expect_refused(kHeader, 4, "", "no samples");
  expect_refused(kHeader + row + "0.002,5,0.1,,0.1,0.2,0.1,0.2\n", 6, "q_desired_A2_rad",
                 "is not a number");
}

TEST_F(JointErrorFiles, HeaderGivenAtCommitWritesTheSameBytes) {
  // The truth is write_joint_errors_csv's file of the same log; the rows' waiting file is gone
  // after the commit, and after a writer dropped without one (which leaves no output).
  const ident::JointErrorLog log = random_log();
  const auto whole = dir_ / "whole.csv", deferred = dir_ / "deferred.csv";
  ident::write_joint_errors_csv(whole, log);
  {
    ident::JointErrorsCsvWriter out(deferred, log.joint_count(), true);
    std::vector<double> desired(3), measured(3), internal(3);
    for (std::size_t k = 0; k < log.sample_count(); ++k) {
      for (std::size_t j = 0; j < 3; ++j) {
        desired[j] = log.q_desired_rad[j][k];
        measured[j] = log.q_measured_rad[j][k];
        internal[j] = log.q_internal_rad[j][k];
      }
      out.add(log.time_s[k], log.payload_kg[k], desired, measured, internal);
    }
    EXPECT_THROW(out.commit(), std::logic_error);  // its header is still to come
    out.commit(log);
  }
  EXPECT_EQ(imscal::test_support::read_text(deferred), imscal::test_support::read_text(whole));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "deferred.csv.rows"));
  const auto dropped = dir_ / "dropped.csv";
  {
    ident::JointErrorsCsvWriter out(dropped, 3, true);
    const std::vector<double> zero(3, 0.0);
    out.add(0.0, 5.0, zero, zero, zero);
    EXPECT_TRUE(std::filesystem::exists(dir_ / "dropped.csv.rows"));
  }
  EXPECT_FALSE(std::filesystem::exists(dropped));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "dropped.csv.rows"));
}

TEST_F(JointErrorFiles, MissingFileRefused) {
  EXPECT_THROW(ident::read_joint_errors_csv(dir_ / "none.csv"), imscal::InputError);
}

TEST_F(JointErrorFiles, Sha256OfKnownText) {
  // FIPS 180-2 test vectors: "abc", and the 56-byte two-block message.
  std::ofstream(dir_ / "abc") << "abc";
  EXPECT_EQ(ident::file_sha256_hex(dir_ / "abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  std::ofstream(dir_ / "two") << "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  EXPECT_EQ(ident::file_sha256_hex(dir_ / "two"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

}  // namespace
