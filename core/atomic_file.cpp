#include "core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <fmt/format.h>
#include <atomic>
#include <cerrno>
#include <cstring>
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

// fsync: on some file systems a full disk shows only here. Returns errno, 0 on success.
int sync_file(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return errno;
  const int result = ::fsync(fd) == 0 ? 0 : errno;
  ::close(fd);
  return result;
}

std::string reason(int error) {
  return error != 0 ? std::strerror(error) : "unknown reason";
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
  errno = 0;
  out_.open(temporary_, mode);
  if (!out_) {
    throw std::runtime_error(fmt::format("{}: cannot write the output file: {}",
                                         published_path(target_).string(), reason(errno)));
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
  // A write that failed earlier left its reason in errno (later writes to a failed stream make no
  // system call); else flush and close report their own.
  int write_error = out_ ? 0 : errno;
  if (out_) {
    errno = 0;
    out_.flush();
    if (!out_) write_error = errno;
  }
  const bool written = static_cast<bool>(out_);
  errno = 0;
  out_.close();
  if (written && !out_) write_error = errno;
  if (!out_) {
    throw std::runtime_error(fmt::format("{}: writing the output failed: {}",
                                         published_path(target_).string(), reason(write_error)));
  }
  if (const int sync_error = sync_file(temporary_); sync_error != 0) {
    throw std::runtime_error(fmt::format("{}: writing the output failed: {}",
                                         published_path(target_).string(), reason(sync_error)));
  }
  if (overwrite_ == Overwrite::kRefuse && fs::exists(target_)) {
    throw std::runtime_error(fmt::format(
        "{}: output appeared while writing; refusing to overwrite it", target_.string()));
  }
  std::error_code error;
  fs::rename(temporary_, target_, error);
  if (error) {
    throw std::runtime_error(fmt::format("{}: cannot rename temporary output: {}",
                                         published_path(target_).string(), error.message()));
  }
  committed_ = true;
}

fs::path published_path(const fs::path& path) {
  fs::path visible;
  for (const fs::path& part : path)
    if (!part.string().starts_with(kStagingFolderPrefix)) visible /= part;
  return visible;
}

void write_file_atomically(const fs::path& target, std::string_view content, Overwrite overwrite) {
  AtomicFile file(target, overwrite, /*binary=*/true);
  file.stream().write(content.data(), static_cast<std::streamsize>(content.size()));
  file.commit();
}

}  // namespace imscal
