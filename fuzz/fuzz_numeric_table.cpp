// Fuzz target "numeric_table": see fuzz/fuzz_readers.hpp for the reader it exercises.
#include "fuzz/fuzz_input_file.hpp"
#include "fuzz/fuzz_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  imscal::fuzz::read_with("numeric_table",
                          imscal::fuzz::write_input("numeric_table", ".csv", data, size));
  return 0;
}
