#pragma once
// Counts every heap allocation of the test program that includes it (to prove there is none in
// a precontrol cycle): replaces the global operator new/delete, so include it in exactly one
// source file of a test executable. GCC 12 then flags the malloc/free pair at every inlined
// std::allocator use of that file (a false positive: new and delete here are a matching pair);
// the including file silences -Wmismatched-new-delete at its top, before any include.
#include <atomic>
#include <cstdlib>
#include <new>

namespace imscal::test_support {
inline std::atomic<long> g_allocations{0};
}  // namespace imscal::test_support

void* operator new(std::size_t size) {
  ++imscal::test_support::g_allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
