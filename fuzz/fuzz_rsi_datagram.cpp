// Fuzz target "rsi_datagram": see fuzz/fuzz_readers.hpp for the parser it exercises. The parser
// takes the bytes as they come from the socket, not a file.
#include <string_view>

#include "fuzz/fuzz_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  imscal::fuzz::parse_rsi_datagram(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
