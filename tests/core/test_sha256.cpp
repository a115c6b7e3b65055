// core::sha256_hex against the FIPS 180-4 example vectors, its SHA-NI compression against the
// portable one, and, for files of sizes around the
// 64-byte block and the 64 KiB read buffer, against coreutils' sha256sum (a second
// implementation) and ident's file_sha256_hex.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <vector>

#include "core/sha256.hpp"
#include "core/sha256_blocks.hpp"
#include "ident/joint_error_io.hpp"
#include "tests/support/scratch_dir.hpp"

namespace {
class Sha256Test : public imscal::test_support::ScratchDirTest {};

TEST_F(Sha256Test, KnownVectors) {
  EXPECT_EQ(imscal::sha256_hex(""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(imscal::sha256_hex("abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(imscal::sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(imscal::sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST_F(Sha256Test, FilesAgreeWithSha256sumAndIdent) {
  std::mt19937 random(7);
  for (std::size_t size : {0u, 55u, 56u, 63u, 64u, 65u, 119u, 65535u, 65536u, 65600u, 200001u}) {
    const auto file = dir_ / ("data-" + std::to_string(size));
    std::string bytes(size, '\0');
    for (char& c : bytes) c = static_cast<char>(random() & 0xff);
    std::ofstream(file, std::ios::binary) << bytes;
    const std::string ours = imscal::sha256_hex_of_file(file);
    EXPECT_EQ(ours, imscal::sha256_hex(bytes)) << size;
    EXPECT_EQ(ours, imscal::ident::file_sha256_hex(file)) << size;
    FILE* pipe = ::popen(("sha256sum '" + file.string() + "'").c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    char line[128] = {};
    ASSERT_NE(std::fgets(line, sizeof line, pipe), nullptr);
    ::pclose(pipe);
    EXPECT_EQ(ours, std::string(line, 64)) << size;
  }
  EXPECT_THROW(imscal::sha256_hex_of_file(dir_ / "missing"), std::runtime_error);
}
// The SHA-NI blocks against the portable ones (a second implementation) on random blocks, from
// the initial state and from a random one; bit-exact, as a hash must be.
TEST_F(Sha256Test, X86BlocksEqualPortable) {
  if (!imscal::detail::sha256_x86_available()) GTEST_SKIP() << "no SHA extensions here";
  std::mt19937 random(11);
  for (std::size_t blocks : {1u, 2u, 3u, 17u, 1024u}) {
    std::vector<unsigned char> data(64 * blocks);
    for (auto& b : data) b = static_cast<unsigned char>(random() & 0xff);
    imscal::detail::Sha256State portable = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                            0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
    if (blocks == 3)
      for (auto& word : portable) word = random();
    imscal::detail::Sha256State x86 = portable;
    imscal::detail::sha256_blocks_portable(portable, data.data(), blocks);
    imscal::detail::sha256_blocks_x86(x86, data.data(), blocks);
    EXPECT_EQ(portable, x86) << blocks;
  }
}
}  // namespace
