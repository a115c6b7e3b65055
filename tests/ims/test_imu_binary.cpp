// The binary IMU form (.imsb): bit-exact round trips, the same content as the CSV form, the
// byte layout of datasets/FORMAT.md checked against an independent little-endian decoding, and
// damaged files (empty, foreign, truncated in the header or inside a record, trailing bytes, a
// NaN record) refused with the record number and field in the message.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>

#include "core/input_error.hpp"
#include "ims/imu_binary.hpp"
#include "ims/imu_csv.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace fs = std::filesystem;
using imscal::InputError;
using imscal::Overwrite;
using imscal::ims::ImuQuantity;
using imscal::ims::ImuReadOptions;
using imscal::ims::ImuSample;
using imscal::ims::ImuSeries;
using imscal::ims::read_imu_binary;
using imscal::ims::Site;
using imscal::ims::write_imu_binary;
using imscal::test_support::read_text;
using imscal::test_support::write_text;

namespace {

class ImuBinary : public imscal::test_support::ScratchDirTest {};

// Rest for 1 s, then motion; random noise fills all digits.
ImuSeries make_series(std::size_t n, double dt, ImuQuantity quantity, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  ImuSeries s;
  s.quantity = quantity;
  s.nominal_dt_s = dt;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i + 1) * dt;
    const double moving = t > 1.0 ? 1.0 : 0.0;
    Eigen::Vector3d omega = moving * Eigen::Vector3d(0.8 * std::sin(3 * t), 0.4, -0.3) +
                            1e-4 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    Eigen::Vector3d f = moving * Eigen::Vector3d(2 * std::sin(5 * t), 0, 1) +
                        Eigen::Vector3d(0.01, -0.02, 9.80665) +
                        1e-3 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    const double scale = quantity == ImuQuantity::kIncrements ? dt : 1.0;
    s.samples.push_back(ImuSample{t, omega * scale, f * scale});
  }
  return s;
}

std::uint64_t bits(double v) {
  return std::bit_cast<std::uint64_t>(v);
}

void expect_bit_identical(const ImuSeries& a, const ImuSeries& b) {
  ASSERT_EQ(a.samples.size(), b.samples.size());
  EXPECT_EQ(a.quantity, b.quantity);
  EXPECT_EQ(bits(a.nominal_dt_s), bits(b.nominal_dt_s));
  EXPECT_EQ(a.metadata, b.metadata);
  ASSERT_EQ(a.site.has_value(), b.site.has_value());
  if (a.site) {
    EXPECT_EQ(bits(a.site->latitude_deg), bits(b.site->latitude_deg));
    EXPECT_EQ(bits(a.site->longitude_deg), bits(b.site->longitude_deg));
    EXPECT_EQ(bits(a.site->height_m), bits(b.site->height_m));
  }
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    ASSERT_EQ(bits(a.samples[i].t_s), bits(b.samples[i].t_s)) << i;
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(bits(a.samples[i].gyro[k]), bits(b.samples[i].gyro[k])) << i;
      ASSERT_EQ(bits(a.samples[i].acc[k]), bits(b.samples[i].acc[k])) << i;
    }
  }
}

// Independent decoding of a little-endian IEEE double, byte by byte.
double le_double(const std::string& bytes, std::size_t offset) {
  std::uint64_t raw = 0;
  for (int b = 7; b >= 0; --b) {
    raw = (raw << 8) | static_cast<unsigned char>(bytes.at(offset + static_cast<std::size_t>(b)));
  }
  return std::bit_cast<double>(raw);
}

std::string error_of(const fs::path& file, std::string* field = nullptr) {
  try {
    read_imu_binary(file);
  } catch (const InputError& e) {
    if (field != nullptr) *field = e.field();
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos);
    return e.what();
  }
  ADD_FAILURE() << file << " was accepted";
  return {};
}

TEST_F(ImuBinary, RoundTripIsBitExactAndMatchesTheCsvForm) {
  for (ImuQuantity q : {ImuQuantity::kIncrements, ImuQuantity::kRates}) {
    ImuSeries s = make_series(2500, 0.002, q, 21);
    s.site = Site{-33.9, 151.2, 40.0};
    s.metadata = {{"sensor", "RLG triad"}, {"empty", ""}};
    const fs::path binary = dir_ / "r.imsb", csv = dir_ / "r.csv";
    write_imu_binary(binary, s, Overwrite::kAllow);
    write_imu_csv(csv, s, Overwrite::kAllow);
    const ImuSeries from_binary = read_imu_binary(binary);
    expect_bit_identical(s, from_binary);
    expect_bit_identical(imscal::ims::read_imu_csv(csv), from_binary);
    EXPECT_EQ(from_binary.first_data_line, 0u);
    EXPECT_EQ(from_binary.source, binary.string());
  }
  // No site: stays absent.
  const ImuSeries s = make_series(600, 0.002, ImuQuantity::kRates, 1);
  write_imu_binary(dir_ / "nosite.imsb", s, Overwrite::kAllow);
  expect_bit_identical(s, read_imu_binary(dir_ / "nosite.imsb"));
}

TEST_F(ImuBinary, ByteLayoutIsTheDocumentedOne) {
  ImuSeries s = make_series(3, 0.25, ImuQuantity::kRates, 4);
  s.metadata = {{"k", "vv"}};
  const fs::path file = dir_ / "layout.imsb";
  write_imu_binary(file, s, Overwrite::kAllow);
  const std::string b = read_text(file);
  // magic 8, version 4, quantity 4, dt 8, has_site 4, site 24, count 4, "k" 4+1, "vv" 4+2,
  // records 8, then 3 x 56 bytes.
  const std::size_t header = 8 + 4 + 4 + 8 + 4 + 24 + 4 + 5 + 6 + 8;
  ASSERT_EQ(b.size(), header + 3 * 56);
  EXPECT_EQ(b.substr(0, 8), std::string("IMSB\r\n\x1a\n", 8));
  EXPECT_EQ(b[8], 1);   // version, little-endian
  EXPECT_EQ(b[12], 1);  // rates
  EXPECT_EQ(le_double(b, 16), 0.25);
  EXPECT_EQ(b.substr(56, 4), std::string("\x01\x00\x00\x00", 4));
  EXPECT_EQ(b.substr(60, 5), std::string("k\x02\x00\x00\x00", 5));  // key, value length
  EXPECT_EQ(b[header - 8], 3);                                      // record count
  for (std::size_t r = 0; r < 3; ++r) {
    const ImuSample& x = s.samples[r];
    const std::size_t at = header + 56 * r;
    EXPECT_EQ(le_double(b, at), x.t_s);
    EXPECT_EQ(le_double(b, at + 8), x.gyro.x());
    EXPECT_EQ(le_double(b, at + 48), x.acc.z());
  }
}

TEST_F(ImuBinary, EmptyForeignAndWrongVersionFilesAreRefused) {
  write_text(dir_ / "empty.imsb", "");
  std::string field;
  EXPECT_NE(error_of(dir_ / "empty.imsb", &field).find("empty"), std::string::npos);
  EXPECT_EQ(field, "magic");
  write_text(dir_ / "text.imsb", "# imscal-imu: 1\n# quantity: rates\n");
  EXPECT_NE(error_of(dir_ / "text.imsb", &field).find("not an imscal IMU binary file"),
            std::string::npos);
  EXPECT_EQ(field, "magic");
  write_imu_binary(dir_ / "v.imsb", make_series(600, 0.002, ImuQuantity::kRates, 2),
                   Overwrite::kAllow);
  std::string b = read_text(dir_ / "v.imsb");
  b[8] = 2;
  write_text(dir_ / "v2.imsb", b);
  EXPECT_NE(error_of(dir_ / "v2.imsb", &field).find("unsupported version 2"), std::string::npos);
  EXPECT_EQ(field, "version");
}

TEST_F(ImuBinary, TruncationIsDetectedByTheSizeCheck) {
  const fs::path whole = dir_ / "whole.imsb";
  write_imu_binary(whole, make_series(600, 0.002, ImuQuantity::kRates, 3), Overwrite::kAllow);
  const std::string b = read_text(whole);
  const std::size_t header = b.size() - 600 * 56;
  std::string field;
  // Inside record 401, after its t_s and gyro_x (16 of 56 bytes).
  write_text(dir_ / "cut_record.imsb", b.substr(0, header + 400 * 56 + 16));
  std::string message = error_of(dir_ / "cut_record.imsb", &field);
  EXPECT_NE(message.find("record 401 of 600"), std::string::npos) << message;
  EXPECT_NE(message.find("truncated"), std::string::npos) << message;
  EXPECT_EQ(field, "gyro_y_rad_s");
  // Exactly at a record boundary: record 600 is missing whole.
  write_text(dir_ / "cut_boundary.imsb", b.substr(0, header + 599 * 56));
  message = error_of(dir_ / "cut_boundary.imsb", &field);
  EXPECT_NE(message.find("record 600 of 600"), std::string::npos) << message;
  EXPECT_EQ(field, "t_s");
  // Inside the header.
  write_text(dir_ / "cut_header.imsb", b.substr(0, 20));
  message = error_of(dir_ / "cut_header.imsb", &field);
  EXPECT_NE(message.find("truncated header"), std::string::npos) << message;
  EXPECT_EQ(field, "nominal_dt_s");
  // Extra bytes after the last record.
  write_text(dir_ / "long.imsb", b + "xyz");
  message = error_of(dir_ / "long.imsb", &field);
  EXPECT_NE(message.find("3 bytes follow the 600 records"), std::string::npos) << message;
  EXPECT_EQ(field, "sample_count");
  // A metadata length running past the end.
  std::string corrupt = b;
  corrupt[52] = 1;                                // one metadata entry...
  corrupt.replace(56, 4, "\xff\xff\x00\x00", 4);  // ...of 65535 bytes
  write_text(dir_ / "meta.imsb", corrupt);
  message = error_of(dir_ / "meta.imsb", &field);
  EXPECT_EQ(field, "metadata");
}

TEST_F(ImuBinary, NanRecordNamesRecordAndField) {
  const fs::path whole = dir_ / "whole.imsb";
  write_imu_binary(whole, make_series(600, 0.002, ImuQuantity::kIncrements, 8), Overwrite::kAllow);
  std::string b = read_text(whole);
  const std::size_t header = b.size() - 600 * 56;
  const double nan = std::nan("");
  std::memcpy(b.data() + header + 99 * 56 + 5 * 8, &nan, 8);  // record 100, dv_y (x86: LE)
  write_text(dir_ / "nan.imsb", b);
  std::string field;
  const std::string message = error_of(dir_ / "nan.imsb", &field);
  EXPECT_NE(message.find("record 100 of 600"), std::string::npos) << message;
  EXPECT_EQ(field, "dv_y_m_s");
}

// Records are decoded in chunks of 4096: the total in the message is the file's, not the chunk's.
TEST_F(ImuBinary, NanRecordOfALongFileNamesTheFileTotal) {
  const fs::path whole = dir_ / "long.imsb";
  write_imu_binary(whole, make_series(10000, 0.002, ImuQuantity::kIncrements, 9),
                   Overwrite::kAllow);
  std::string b = read_text(whole);
  const std::size_t header = b.size() - 10000 * 56;
  const double nan = std::nan("");
  std::memcpy(b.data() + header + 101 * 56 + 1 * 8, &nan, 8);  // record 102, dtheta_x
  write_text(dir_ / "nan.imsb", b);
  std::string field;
  const std::string message = error_of(dir_ / "nan.imsb", &field);
  EXPECT_NE(message.find("record 102 of 10000"), std::string::npos) << message;
}

TEST_F(ImuBinary, FailedWritesLeaveNothingBehind) {
  ImuSeries s = make_series(100, 0.01, ImuQuantity::kRates, 5);
  s.samples[99].t_s = INFINITY;
  EXPECT_THROW(write_imu_binary(dir_ / "inf.imsb", s, Overwrite::kAllow), std::invalid_argument);
  EXPECT_TRUE(fs::is_empty(dir_));
  write_text(dir_ / "old.imsb", "old");
  EXPECT_THROW(write_imu_binary(dir_ / "old.imsb", make_series(5, 0.01, ImuQuantity::kRates, 5),
                                Overwrite::kRefuse),
               std::runtime_error);
  EXPECT_EQ(read_text(dir_ / "old.imsb"), "old");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

}  // namespace
