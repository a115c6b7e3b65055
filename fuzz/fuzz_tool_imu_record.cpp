// Fuzz target "tool_imu_record": see fuzz/fuzz_readers.hpp for the reader it exercises.
#include "fuzz/fuzz_input_file.hpp"
#include "fuzz/fuzz_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  imscal::fuzz::read_with("tool_imu_record",
                          imscal::fuzz::write_input("tool_imu_record", ".csv", data, size));
  return 0;
}
