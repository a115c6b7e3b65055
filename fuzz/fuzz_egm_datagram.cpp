// Fuzz target "egm_datagram": see fuzz/fuzz_readers.hpp for the codec it exercises. The codec
// takes the bytes as they come from the socket, not a file.
#include <string_view>

#include "fuzz/fuzz_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  imscal::fuzz::parse_egm_datagram(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
