// Fuzz target "tracker_poses": see fuzz/fuzz_readers.hpp for the reader it exercises.
#include "fuzz/fuzz_input_file.hpp"
#include "fuzz/fuzz_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  imscal::fuzz::read_with("tracker_poses",
                          imscal::fuzz::write_input("tracker_poses", ".csv", data, size));
  return 0;
}
