// Big packets in sealed memfds (see packet_memfd.hpp). Raw system calls: in the preload library
// fstat, fcntl and pwrite are its own interposed versions, and these descriptors are none of
// the host's business.
#include "linux/packet_memfd.hpp"

#include "linux/protocol.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>

namespace l6470emu {

namespace {

constexpr int kRequiredSeals = F_SEAL_WRITE | F_SEAL_GROW | F_SEAL_SHRINK;

void close_keeping_errno(int fd) {
  const int e = errno;
  syscall(SYS_close, fd);
  errno = e;
}

bool write_all(int fd, const std::uint8_t* p, std::size_t n, std::size_t at) {
  while (n > 0) {
    const long w = syscall(SYS_pwrite64, fd, p, n, static_cast<off_t>(at));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      if (w == 0) errno = EIO;
      return false;
    }
    p += w;
    n -= static_cast<std::size_t>(w);
    at += static_cast<std::size_t>(w);
  }
  return true;
}

}  // namespace

int seal_packet(const void* header, std::size_t header_size, std::span<const std::uint8_t> payload) {
  const std::size_t total = header_size + payload.size();
  if (total > kMaxPacket) {
    errno = EMSGSIZE;
    return -1;
  }
  const int fd = static_cast<int>(syscall(SYS_memfd_create, "l6470emu-packet", MFD_CLOEXEC | MFD_ALLOW_SEALING));
  if (fd < 0) return -1;
  // The size first (one allocation of the file's length), then the bytes, then the seals.
  if (syscall(SYS_ftruncate, fd, static_cast<off_t>(total)) != 0 ||
      !write_all(fd, static_cast<const std::uint8_t*>(header), header_size, 0) ||
      !write_all(fd, payload.data(), payload.size(), header_size) ||
      syscall(SYS_fcntl, fd, F_ADD_SEALS, kRequiredSeals | F_SEAL_SEAL) != 0) {
    close_keeping_errno(fd);
    return -1;
  }
  return fd;
}

bool load_packet(int fd, std::uint64_t size, std::uint8_t* into) {
  struct stat st{};
  if (fd < 0 || size > kMaxPacket || syscall(SYS_fstat, fd, &st) != 0 || !S_ISREG(st.st_mode) ||
      st.st_size < 0 || static_cast<std::uint64_t>(st.st_size) != size) {
    errno = EPROTO;
    return false;
  }
  // Only memfds (shmem) know seals: any other file (a FIFO, a FUSE file that could block, a
  // plain file) fails F_GET_SEALS with EINVAL; an unsealed memfd could change under us.
  const long seals = syscall(SYS_fcntl, fd, F_GET_SEALS);
  if (seals < 0 || (seals & kRequiredSeals) != kRequiredSeals) {
    errno = EPROTO;
    return false;
  }
  std::size_t done = 0;
  while (done < size) {
    const long r = syscall(SYS_pread64, fd, into + done, static_cast<std::size_t>(size) - done, static_cast<off_t>(done));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) {
      errno = EPROTO;
      return false;
    }
    done += static_cast<std::size_t>(r);
  }
  return true;
}

}  // namespace l6470emu
