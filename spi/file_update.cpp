// update_file_locked: flock(2) on the file, then a temporary file renamed over it.
#include "spi/file_update.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace l6470emu {

namespace {

std::string errno_text(int e) { return std::strerror(e); }

bool read_all(int fd, std::string& out) {
  out.clear();
  char buf[65536];
  off_t at = 0;
  for (;;) {
    const ssize_t n = pread(fd, buf, sizeof buf, at);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (n == 0) return true;
    out.append(buf, static_cast<std::size_t>(n));
    at += n;
  }
}

bool write_all(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = write(fd, text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  return true;
}

std::string directory_of(const std::string& path) {
  const auto slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

}  // namespace

std::string update_file_locked(const std::string& named, const FileTransform& transform) {
  if (named.empty()) return "no file named";
  // A symbolic link is followed: the file it names is updated (and renamed over), the link kept.
  std::string path = named;
  struct stat link {};
  if (lstat(named.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) {
    char* target = realpath(named.c_str(), nullptr);
    if (target == nullptr) return named + ": a link to " + errno_text(errno);
    path = target;
    std::free(target);
  }
  // Lock the file itself; once locked, make sure it is still the one at `path` (another
  // process may have renamed its new text over it while this one waited).
  int fd = -1;
  for (int attempt = 0; attempt < 1000 && fd < 0; ++attempt) {
    fd = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) return path + ": " + errno_text(errno);
    while (flock(fd, LOCK_EX) != 0)
      if (errno != EINTR) {
        const int e = errno;
        close(fd);
        return path + ": cannot lock: " + errno_text(e);
      }
    struct stat held {}, now {};
    if (fstat(fd, &held) != 0 || stat(path.c_str(), &now) != 0 || held.st_ino != now.st_ino || held.st_dev != now.st_dev) {
      close(fd);
      fd = -1;
    }
  }
  if (fd < 0) return path + ": replaced too often while waiting for its lock";
  std::string text, error;
  if (!read_all(fd, text)) {
    error = path + ": " + errno_text(errno);
    close(fd);
    return error;
  }
  const std::string out = transform(text, error);
  if (!error.empty()) {
    close(fd);
    return error;
  }
  const std::string temp = path + ".tmp." + std::to_string(getpid());
  const int t = open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (t < 0) {
    error = temp + ": " + errno_text(errno);
  } else {
    if (!write_all(t, out) || fsync(t) != 0) error = temp + ": " + errno_text(errno);
    close(t);
    if (error.empty() && rename(temp.c_str(), path.c_str()) != 0) error = path + ": " + errno_text(errno);
    if (!error.empty()) unlink(temp.c_str());
  }
  close(fd);  // the lock goes with it
  return error;
}

std::string file_writable(const std::string& path) {
  if (path.empty()) return "the file name is empty";
  struct stat st {};
  if (stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) return path + ": a directory";
    if (!S_ISREG(st.st_mode)) return path + ": not a regular file";
    if (access(path.c_str(), R_OK | W_OK) != 0) return path + ": " + errno_text(errno);
  }
  // The file is replaced by a rename: its folder must take a new file.
  const std::string dir = directory_of(path);
  if (access(dir.c_str(), W_OK | X_OK) != 0) return path + ": cannot write in " + dir + ": " + errno_text(errno);
  return "";
}

}  // namespace l6470emu
