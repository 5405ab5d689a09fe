// The program's side of run's progress line (linux/preload/progress.hpp): two 64-bit words in a
// shared mapping, each stored whole with a relaxed atomic store (one instruction): no system
// call on the path of a message or a move of time.
#include "linux/preload/progress.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>

#include "board/run_report.hpp"
#include "linux/preload/real.hpp"

namespace l6470emu::preload {

namespace detail {
std::atomic<std::uint64_t>* g_progress = nullptr;
}

void start_progress() {
  const char* path = std::getenv(kRunProgressEnv);
  if (!path || !*path || detail::g_progress) return;
  const int fd = real::open(path, O_RDWR | O_CLOEXEC, 0);
  if (fd < 0) return;
  void* m = mmap(nullptr, kRunProgressBytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  real::close(fd);
  if (m != MAP_FAILED) detail::g_progress = static_cast<std::atomic<std::uint64_t>*>(m);
}

}  // namespace l6470emu::preload
