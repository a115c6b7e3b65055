// Fuzz target "identification_report": see fuzz/fuzz_readers.hpp for the reader it exercises.
#include "fuzz/fuzz_input_file.hpp"
#include "fuzz/fuzz_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  imscal::fuzz::read_with("identification_report",
                          imscal::fuzz::write_input("identification_report", ".json", data, size));
  return 0;
}
