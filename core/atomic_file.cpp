#include "core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <fmt/format.h>
#include <atomic>
#include <stdexcept>
#include <system_error>

namespace imscal {
namespace fs = std::filesystem;

namespace {
fs::path temporary_name(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  return target.parent_path() /
         fmt::format(".{}.tmp-{}-{}", target.filename().string(), ::getpid(), counter++);
}

void sync_file(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}
}  // namespace

AtomicFile::AtomicFile(fs::path target, Overwrite overwrite, bool binary)
    : target_(std::move(target)), temporary_(temporary_name(target_)), overwrite_(overwrite) {
  if (overwrite_ == Overwrite::kRefuse && fs::exists(target_)) {
    throw std::runtime_error(fmt::format(
        "{}: output exists already; refusing to overwrite it (use --force)", target_.string()));
  }
  auto mode = std::ios::out | std::ios::trunc;
  if (binary) mode |= std::ios::binary;
  out_.open(temporary_, mode);
  if (!out_) {
    throw std::runtime_error(
        fmt::format("{}: cannot create temporary output file", temporary_.string()));
  }
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ignored;
    fs::remove(temporary_, ignored);
  }
}

void AtomicFile::commit() {
  out_.flush();
  if (!out_) {
    throw std::runtime_error(fmt::format("{}: write failed", temporary_.string()));
  }
  out_.close();
  sync_file(temporary_);
  if (overwrite_ == Overwrite::kRefuse && fs::exists(target_)) {
    throw std::runtime_error(fmt::format(
        "{}: output appeared while writing; refusing to overwrite it", target_.string()));
  }
  std::error_code error;
  fs::rename(temporary_, target_, error);
  if (error) {
    throw std::runtime_error(
        fmt::format("{}: cannot rename temporary output: {}", target_.string(), error.message()));
  }
  committed_ = true;
}

void write_file_atomically(const fs::path& target, std::string_view content, Overwrite overwrite) {
  AtomicFile file(target, overwrite, /*binary=*/true);
  file.stream().write(content.data(), static_cast<std::streamsize>(content.size()));
  file.commit();
}

}  // namespace imscal
