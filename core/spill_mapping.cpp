// Temporary-file mappings whose pages are dropped from the page table behind their readers
// (core/spill_mapping.hpp).
#include "core/spill_mapping.hpp"

#include <fmt/format.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace imscal {
namespace {

// The live mappings and the thread that drops their pages. Mapping, growing and unmapping
// happen under the mutex, so the thread never advises a range that is no longer (or not yet)
// one of ours: MADV_DONTNEED on anonymous memory would zero it.
class ResidentPageRelease {
 public:
  static ResidentPageRelease& instance() {
    // Never destroyed: the thread may still run while static objects are destroyed at exit.
    static ResidentPageRelease* release = new ResidentPageRelease;
    return *release;
  }
  std::mutex& mutex() { return mutex_; }
  // Callers hold mutex().
  void add(std::byte* data, std::size_t bytes) {
    mappings_[data] = bytes;
    if (!thread_started_) {
      std::thread([this] { run(); }).detach();
      thread_started_ = true;
    }
  }
  void remove(std::byte* data) { mappings_.erase(data); }

 private:
  [[noreturn]] void run() {
    std::unique_lock lock(mutex_);
    for (;;) {
      wake_.wait_for(lock, kResidentReleasePeriod);
      for (const auto& [data, bytes] : mappings_) madvise(data, bytes, MADV_DONTNEED);
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;  // never notified: a timed wait
  std::map<std::byte*, std::size_t> mappings_;
  bool thread_started_ = false;
};

[[noreturn]] void refuse(const char* what, const char* step) {
  throw std::runtime_error(
      fmt::format("cannot keep {} in a temporary file ({}: {})", what, step, std::strerror(errno)));
}

// An anonymous temporary file's descriptor (deleted when closed).
int temporary_file(const char* what) {
  std::FILE* file = std::tmpfile();
  if (file == nullptr) refuse(what, "tmpfile");
  const int fd = dup(fileno(file));
  std::fclose(file);
  if (fd < 0) refuse(what, "dup");
  return fd;
}

}  // namespace

void watch_resident_pages(const void* data, std::size_t bytes) {
  ResidentPageRelease& release = ResidentPageRelease::instance();
  std::lock_guard lock(release.mutex());
  release.add(static_cast<std::byte*>(const_cast<void*>(data)), bytes);
}

void unwatch_resident_pages(const void* data) {
  ResidentPageRelease& release = ResidentPageRelease::instance();
  std::lock_guard lock(release.mutex());
  release.remove(static_cast<std::byte*>(const_cast<void*>(data)));
}

SpillMapping::~SpillMapping() {
  if (data_ != nullptr) {
    ResidentPageRelease& release = ResidentPageRelease::instance();
    std::lock_guard lock(release.mutex());
    release.remove(data_);
    munmap(data_, capacity_);
  }
  if (fd_ >= 0) close(fd_);
}

void SpillMapping::reserve(std::size_t bytes, const char* what) {
  if (bytes <= capacity_) return;
  const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
  const std::size_t grown = (bytes + page - 1) / page * page;
  if (fd_ < 0) fd_ = temporary_file(what);
  if (ftruncate(fd_, off_t(grown)) != 0) refuse(what, "ftruncate");
  ResidentPageRelease& release = ResidentPageRelease::instance();
  std::lock_guard lock(release.mutex());
  void* mapped = data_ == nullptr ? mmap(nullptr, grown, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0)
                                  : mremap(data_, capacity_, grown, MREMAP_MAYMOVE);
  if (mapped == MAP_FAILED) refuse(what, data_ == nullptr ? "mmap" : "mremap");
  if (data_ != nullptr) release.remove(data_);
  data_ = static_cast<std::byte*>(mapped);
  capacity_ = grown;
  release.add(data_, capacity_);
}

}  // namespace imscal
