#pragma once
// SHA-256's compression function (FIPS 180-4, 6.2.2) over whole 64-byte blocks: a portable
// version and one with the x86 SHA extensions (SHA-NI), about five times faster, chosen at run
// time. The run folder hashes every stage's inputs and outputs, some of them tens of megabytes.
#include <array>
#include <cstddef>
#include <cstdint>

namespace imscal::detail {

using Sha256State = std::array<std::uint32_t, 8>;

// Compresses `blocks` consecutive 64-byte blocks at `data` into `state`, with the fastest
// version this processor runs.
void sha256_blocks(Sha256State& state, const unsigned char* data, std::size_t blocks);

// The portable version.
void sha256_blocks_portable(Sha256State& state, const unsigned char* data, std::size_t blocks);

// Whether this processor has the SHA extensions (and SSSE3 and SSE4.1, which the version uses).
bool sha256_x86_available();
// The SHA-NI version; only where sha256_x86_available().
void sha256_blocks_x86(Sha256State& state, const unsigned char* data, std::size_t blocks);

}  // namespace imscal::detail
