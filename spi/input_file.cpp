#include "spi/input_file.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace l6470emu {

int open_input_file(const std::string& path, std::string& error, int fifo_wait_ms) {
  // stat first: opening a device can block or have effects of its own.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int e = errno;
    error = std::string("cannot be read (") + std::strerror(e) + ")";
    errno = e;
    return -1;
  }
  errno = 0;  // below: refusals of what the file is, not the system's errors
  if (S_ISDIR(st.st_mode)) {
    error = "is a directory";
    return -1;
  }
  if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) {
    error = "is a device, not a file: it could block or never end";
    return -1;
  }
  if (S_ISSOCK(st.st_mode)) {
    error = "is a socket, not a file";
    return -1;
  }
  if (!S_ISREG(st.st_mode) && !S_ISFIFO(st.st_mode)) {
    error = "is not a regular file";
    return -1;
  }
  // O_NONBLOCK: a FIFO opens at once even before its writer does; reads are blocking again below.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) {
    const int e = errno;
    error = std::string("cannot be read (") + std::strerror(e) + ")";
    errno = e;
    return -1;
  }
  if (S_ISFIFO(st.st_mode)) {
    // Until a writer comes, Linux reports nothing on a FIFO opened for reading: wait for data or
    // for a writer that came and went (POLLHUP), a bounded time.
    pollfd p{fd, POLLIN, 0};
    int r;
    while ((r = ::poll(&p, 1, fifo_wait_ms)) < 0 && errno == EINTR) {
    }
    if (r <= 0) {
      ::close(fd);
      error = "is a FIFO that nothing wrote to within " + std::to_string(fifo_wait_ms / 1000) +
              (fifo_wait_ms % 1000 ? "." + std::to_string(fifo_wait_ms % 1000 / 100) : std::string()) + " s";
      return -1;
    }
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  return fd;
}

std::optional<std::string> read_input_file(const std::string& path, std::size_t max_bytes, std::string& error) {
  const int fd = open_input_file(path, error);
  if (fd < 0) return std::nullopt;
  std::string text(max_bytes + 1, '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      error = std::string("cannot be read (") + std::strerror(errno) + ")";
      ::close(fd);
      return std::nullopt;
    }
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  text.resize(got);
  return text;
}

}  // namespace l6470emu
