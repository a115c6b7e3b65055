#pragma once
// Transparent huge pages for a large sample buffer that a reader fills at once (ims/imu_csv.hpp,
// ims/imu_binary.hpp): an hour at 2 kHz is 400 MB, and faulting it in 4 KiB pages costs more than
// decoding it.
#include <cstddef>

namespace imscal::ims {

// Asks the kernel for huge pages on the whole 2 MiB pages inside [data, data + bytes) when the
// buffer spans at least four of them. Only a hint (madvise MADV_HUGEPAGE); ignored where
// unsupported, and the buffer's contents are untouched.
void advise_huge_pages(const void* data, std::size_t bytes);

}  // namespace imscal::ims
