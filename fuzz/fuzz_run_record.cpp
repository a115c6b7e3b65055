// Fuzz target "run_record": see fuzz/fuzz_readers.hpp for the reader it exercises.
#include "fuzz/fuzz_input_file.hpp"
#include "fuzz/fuzz_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  imscal::fuzz::read_with("run_record",
                          imscal::fuzz::write_input("run_record", ".json", data, size));
  return 0;
}
