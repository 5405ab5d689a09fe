// check_recording_path: one non-blocking, non-following open(2) and an fstat(2).
#include "linux/recording_path.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace l6470emu {

void check_recording_path(const std::string& path) {
  // Only a regular file, never through a symbolic link, and nothing that could block: a FIFO
  // opened for writing waits for a reader (a daemon holding its board's lock would wait with it),
  // and a root daemon must not follow another user's link to overwrite what it names.
  int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0 && errno == ENOENT) fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) {
    if (errno == ELOOP) throw std::runtime_error(path + ": a symbolic link: name the file itself");
    throw std::runtime_error(path + ": cannot create: " + std::strerror(errno));
  }
  struct stat st {};
  const bool regular = fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  ::close(fd);
  if (!regular) throw std::runtime_error(path + ": not a regular file (a device, a FIFO or a directory): a trace goes to a file");
}

std::unique_ptr<TraceOutput> open_host_recording_output(const std::string& path, std::function<std::int64_t()> clock) {
  check_recording_path(path);
  return open_recording_output(path, std::move(clock));
}

}  // namespace l6470emu
