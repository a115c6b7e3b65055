#include "core/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sstream>

#include "core/input_error.hpp"

namespace imscal {
namespace fs = std::filesystem;

namespace {

// What a non-regular file is, for the refusal.
const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a named pipe (FIFO)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  return "not a plain file";
}

[[noreturn]] void refuse(const fs::path& file, const std::string& problem) {
  throw InputError(file.string(), 0, "", problem);
}

}  // namespace

int open_regular_file(const fs::path& file) {
  // O_NONBLOCK: opening a FIFO without a writer would otherwise wait forever.
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) refuse(file, std::string("cannot open the file: ") + std::strerror(errno));
  struct stat status {};
  if (::fstat(fd, &status) != 0) {
    const int error = errno;
    ::close(fd);
    refuse(file, std::string("cannot read the file's status: ") + std::strerror(error));
  }
  if (!S_ISREG(status.st_mode)) {
    ::close(fd);
    refuse(file, std::string("is ") + kind_of(status.st_mode) + ", not a regular file");
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  return fd;
}

std::ifstream open_input_stream(const fs::path& file) {
  ::close(open_regular_file(file));
  errno = 0;
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    refuse(file, std::string("cannot open the file: ") +
                     (errno != 0 ? std::strerror(errno) : "unknown reason"));
  }
  return in;
}

void throw_if_read_failed(const std::istream& in, const fs::path& file) {
  if (in.bad()) refuse(file, std::string("cannot read the file: ") + std::strerror(errno));
}

std::string read_input_file(const fs::path& file) {
  std::ifstream in = open_input_stream(file);
  std::ostringstream text;
  if (in.peek() != std::char_traits<char>::eof()) text << in.rdbuf();
  throw_if_read_failed(in, file);
  return text.str();
}

bool strip_byte_order_mark(std::string& first_line) {
  if (!first_line.starts_with(kUtf8ByteOrderMark)) return false;
  first_line.erase(0, kUtf8ByteOrderMark.size());
  return true;
}

}  // namespace imscal
