// Fuzz target "psins_attitude": see fuzz/fuzz_readers.hpp for the reader it exercises.
#include "fuzz/fuzz_input_file.hpp"
#include "fuzz/fuzz_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  imscal::fuzz::read_with("psins_attitude",
                          imscal::fuzz::write_input("psins_attitude", ".csv", data, size));
  return 0;
}
