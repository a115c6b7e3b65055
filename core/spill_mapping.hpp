#pragma once
// Bytes in an anonymous temporary file mapped into memory (MAP_SHARED, read and write), for
// arrays that grow with a record (core/spillable_vector.hpp). The kernel counts a mapped page in
// the process' resident memory only while it is in the page table: a background thread drops
// every mapping's pages from the page table (madvise MADV_DONTNEED) every
// kResidentReleasePeriod, so what stays resident is what was touched since (the pages stay in
// the page cache, dirty ones are written to the file, and the next access maps them again with
// the same bytes). Addresses stay valid until the mapping is grown or destroyed: a view into it
// behaves as one into a std::vector's buffer.
#include <chrono>
#include <cstddef>

namespace imscal {

inline constexpr std::chrono::milliseconds kResidentReleasePeriod{100};

// A read-only file mapping owned elsewhere (a file's text read in one pass) whose pages the
// same thread drops: watch it after mapping, unwatch it before unmapping.
void watch_resident_pages(const void* data, std::size_t bytes);
void unwatch_resident_pages(const void* data);

class SpillMapping {
 public:
  // An empty mapping (no file yet).
  SpillMapping() = default;
  ~SpillMapping();
  SpillMapping(const SpillMapping&) = delete;
  SpillMapping& operator=(const SpillMapping&) = delete;

  // Room for at least `bytes` (the file and the mapping grown; the contents kept, the address
  // may change). Throws std::runtime_error naming `what` when no temporary file can be made or
  // grown (a full disk).
  void reserve(std::size_t bytes, const char* what);

  std::byte* data() const { return data_; }
  std::size_t capacity() const { return capacity_; }

 private:
  int fd_ = -1;
  std::byte* data_ = nullptr;
  std::size_t capacity_ = 0;  // bytes mapped
};

}  // namespace imscal
