#include "core/sha256.hpp"

#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <fstream>
#include <vector>

#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "core/sha256_blocks.hpp"

namespace imscal {
namespace {

// Incremental hash: feed bytes in any pieces, then finish().
class Sha256 {
 public:
  void feed(const unsigned char* data, std::size_t size) {
    total_bytes_ += size;
    std::size_t i = 0;
    if (buffered_ > 0) {
      while (buffered_ < 64 && i < size) block_[buffered_++] = data[i++];
      if (buffered_ < 64) return;
      compress(block_.data());
      buffered_ = 0;
    }
    const std::size_t blocks = (size - i) / 64;
    detail::sha256_blocks(state_, data + i, blocks);
    i += 64 * blocks;
    while (i < size) block_[buffered_++] = data[i++];
  }

  std::string finish() {
    const std::uint64_t bit_count = total_bytes_ * 8;
    const unsigned char one_bit = 0x80;
    feed(&one_bit, 1);
    const unsigned char zero = 0;
    while (buffered_ != 56) feed(&zero, 1);
    std::array<unsigned char, 8> length{};
    for (int i = 0; i < 8; ++i) length[i] = static_cast<unsigned char>(bit_count >> (56 - 8 * i));
    feed(length.data(), length.size());
    std::string hex;
    for (std::uint32_t word : state_) hex += fmt::format("{:08x}", word);
    return hex;
  }

 private:
  void compress(const unsigned char* block) { detail::sha256_blocks(state_, block, 1); }

  detail::Sha256State state_ = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  std::array<unsigned char, 64> block_{};
  std::size_t buffered_ = 0;
  std::uint64_t total_bytes_ = 0;
};

}  // namespace

std::string sha256_hex(std::string_view bytes) {
  Sha256 hash;
  hash.feed(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  return hash.finish();
}

std::string sha256_hex_of_file(const std::filesystem::path& file) {
  std::ifstream in = open_input_stream(file);
  Sha256 hash;
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    hash.feed(reinterpret_cast<const unsigned char*>(buffer.data()),
              static_cast<std::size_t>(in.gcount()));
  }
  throw_if_read_failed(in, file);
  return hash.finish();
}

}  // namespace imscal
