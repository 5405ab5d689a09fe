// Replaced C library functions that act on open descriptors: ioctl, read, __read_chk and
// write. Emulated descriptors go to the backend with the kernel's argument handling
// (user memory copied in and out, EFAULT, the VFS's own ioctls); others go to the C library
// (but for virtual timerfds, whose reads intercept_timerfd.cpp answers, and, in virtual time, a
// read that would block, which first waits for data as a covered wait: descriptor_wait.hpp).
#include <errno.h>
#include <fcntl.h>
#include <linux/gpio.h>
#include <linux/spi/spidev.h>
#include <stdarg.h>
#include <stddef.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstring>
#include <vector>

#include "linux/preload/descriptor_wait.hpp"
#include "linux/preload/real.hpp"
#include "linux/preload/pwm_sysfs.hpp"
#include "linux/preload/state.hpp"
#include "linux/preload/user_memory.hpp"
#include "linux/preload/virtual_time.hpp"
#include "linux/spidev_rules.hpp"

using namespace l6470emu;
using namespace l6470emu::preload;

namespace {

long fail(long negative_errno) {
  errno = static_cast<int>(-negative_errno);
  return -1;
}

thread_local std::vector<spi_ioc_transfer> t_xfers;
thread_local std::vector<std::uint8_t> t_tx, t_rx;

long spi_message(FdEntry& e, std::size_t n, void* argp) {
  if (n == 0) return 0;
  t_xfers.resize(n);
  if (!copy_from_user(t_xfers.data(), argp, n * sizeof(spi_ioc_transfer))) return fail(-EFAULT);
  const std::uint32_t bufsiz = nodes()[e.node].bufsiz;
  // spidev_message's first loop: sizes against the bounce buffers, before anything is copied.
  if (const long sizes = spidev_message_sizes(bufsiz, t_xfers); sizes < 0) return fail(sizes);
  const std::size_t tx_bytes = spidev_tx_bytes(t_xfers);
  t_tx.resize(tx_bytes);
  std::size_t off = 0, rx_bytes = 0;
  for (const auto& x : t_xfers) {
    if (x.tx_buf) {
      if (!copy_from_user(t_tx.data() + off, reinterpret_cast<const void*>(static_cast<std::uintptr_t>(x.tx_buf)), x.len))
        return fail(-EFAULT);
      off += x.len;
    }
    if (x.rx_buf) rx_bytes += x.len;
  }
  t_rx.resize(rx_bytes);
  const long r = backend()->spi_message(e.handle, t_xfers, t_tx, t_rx);
  if (r < 0) return fail(r);
  off = 0;
  for (const auto& x : t_xfers) {
    if (!x.rx_buf) continue;
    if (!copy_to_user(reinterpret_cast<void*>(static_cast<std::uintptr_t>(x.rx_buf)), t_rx.data() + off, x.len))
      return fail(-EFAULT);
    off += x.len;
  }
  return r;
}

// Offset of the `fd` field of the argument of an fd-creating gpio ioctl, or -1.
long new_fd_offset(unsigned long cmd) {
  if (cmd == GPIO_GET_LINEHANDLE_IOCTL) return offsetof(gpiohandle_request, fd);
  if (cmd == GPIO_GET_LINEEVENT_IOCTL) return offsetof(gpioevent_request, fd);
  if (cmd == GPIO_V2_GET_LINE_IOCTL) return offsetof(gpio_v2_line_request, fd);
  return -1;
}

long generic_ioctl(FdEntry& e, unsigned long cmd, void* argp) {
  const std::size_t size = _IOC_SIZE(cmd);
  const unsigned dir = _IOC_DIR(cmd);
  if (e.kind == HandleKind::spidev && !is_spidev_settings_ioctl(cmd)) return fail(-ENOTTY);
  std::uint8_t buf[1024] = {};
  if (size > sizeof buf) return fail(e.kind == HandleKind::spidev ? -ENOTTY : -EINVAL);
  if ((dir & _IOC_WRITE) && !copy_from_user(buf, argp, size)) return fail(-EFAULT);
  NewFile created;
  const long r = backend()->ioctl(e.handle, cmd, std::span<std::uint8_t>(buf, size), &created, true);
  if (r < 0) return fail(r);
  if (created.fd >= 0) {
    auto* ne = new FdEntry;
    ne->handle = created.handle;
    ne->kind = created.kind;
    ne->node = e.node;
    ne->access = O_RDONLY;  // the kernel's line files are anonymous O_RDONLY files
    ne->record.store(created.kind == HandleKind::line_event_v1     ? sizeof(gpioevent_data)
                     : created.kind == HandleKind::line_request_v2 ? sizeof(gpio_v2_line_event)
                                                                   : 0);
    fd_store(created.fd, ne);
    const long at = new_fd_offset(cmd);
    if (at >= 0 && static_cast<std::size_t>(at) + sizeof(int) <= size) std::memcpy(buf + at, &created.fd, sizeof(int));
  }
  if (e.kind == HandleKind::gpiochip && e.record.load() == 0) {
    if (cmd == GPIO_GET_LINEINFO_WATCH_IOCTL) e.record.store(sizeof(gpioline_info_changed));
    if (cmd == GPIO_V2_GET_LINEINFO_WATCH_IOCTL) e.record.store(sizeof(gpio_v2_line_info_changed));
  }
  if ((dir & _IOC_READ) && !copy_to_user(argp, buf, size)) {
    if (created.fd >= 0) {
      if (FdEntry* t = fd_take(created.fd)) {
        real::close(created.fd);
        fd_release(t);
      }
    }
    return fail(-EFAULT);
  }
  return r;
}

long emulated_ioctl(FdEntry& e, unsigned long cmd, void* argp) {
  if (e.kind == HandleKind::spidev) {
    std::size_t n = 0;
    if (is_spi_message_ioctl(cmd, n)) {
      if (_IOC_SIZE(cmd) % sizeof(spi_ioc_transfer)) return fail(-EINVAL);
      return spi_message(e, n, argp);
    }
  }
  return generic_ioctl(e, cmd, argp);
}

// Virtual time: whether the first queued event may be read now. An event stamped later than
// the program's time (an edge a spidev message caused, queued before the message's end) is
// waited for in virtual time, as is the first one of a blocking read; the board's next edge wakes
// the wait. Returns 0, or -1 with errno (EAGAIN for O_NONBLOCK, EINTR).
int wait_for_record(VirtualHostTime& vt, int fd) {
  const bool nonblocking = real::fcntl(fd, F_GETFL, 0) & O_NONBLOCK;
  for (;;) {
    const Tick t = vt.first_event_tick(fd);
    if (t != kNever && t <= vt.tick_after(0)) return 0;
    if (nonblocking) return static_cast<int>(fail(-EAGAIN));
    const pollfd p{fd, static_cast<short>(t == kNever ? POLLIN : 0), 0};
    VirtualScheduler::Wait w;
    w.deadline = t;
    w.fds = std::span<const pollfd>(&p, 1);
    w.watches_board = true;
    if (vt.wait(w) == VirtualScheduler::End::interrupted) return static_cast<int>(fail(-EINTR));
  }
}

ssize_t read_records(int fd, FdEntry& e, void* buf, std::size_t count) {
  const std::size_t record = e.record.load();
  if (record == 0) return real::read(fd, buf, count);
  if (count < record) return fail(-EINVAL);
  VirtualHostTime* vt = installed_virtual_time();
  if (vt && wait_for_record(*vt, fd) < 0) return -1;
  std::size_t done = 0;
  auto* out = static_cast<std::uint8_t*>(buf);
  while (count - done >= record) {
    // Virtual time: the records after the first stop at one stamped in the program's future.
    if (vt && done > 0) {
      const Tick t = vt->first_event_tick(fd);
      if (t == kNever || t > vt->tick_after(0)) break;
    }
    const ssize_t n = recv(fd, out + done, record, done == 0 ? 0 : MSG_DONTWAIT);
    if (n < 0) {
      if (done > 0) break;  // we have events; the queue is just empty now
      return -1;            // errno from recv: EAGAIN (O_NONBLOCK), EINTR, EFAULT
    }
    if (n == 0) break;  // the board is gone
    done += static_cast<std::size_t>(n);
  }
  return static_cast<ssize_t>(done);
}

// The VFS checks the file's access mode before the driver sees a read or a write.
bool readable(const FdEntry& e) { return e.access == O_RDONLY || e.access == O_RDWR; }
bool writable(const FdEntry& e) { return e.access == O_WRONLY || e.access == O_RDWR; }

ssize_t emulated_read(int fd, FdEntry& e, void* buf, std::size_t count) {
  if (!readable(e)) return fail(-EBADF);
  switch (e.kind) {
    case HandleKind::spidev: {
      if (count > nodes()[e.node].bufsiz) return fail(-EMSGSIZE);
      t_rx.resize(count);
      const long r = backend()->spi_read(e.handle, t_rx);
      if (r < 0) return fail(r);
      if (!copy_to_user(buf, t_rx.data(), count)) return fail(-EFAULT);
      return r;
    }
    case HandleKind::line_handle_v1:
      return fail(-EINVAL);
    default:
      return read_records(fd, e, buf, count);
  }
}

ssize_t emulated_write(FdEntry& e, const void* buf, std::size_t count) {
  if (!writable(e)) return fail(-EBADF);
  if (e.kind != HandleKind::spidev) return fail(-EINVAL);
  if (count > nodes()[e.node].bufsiz) return fail(-EMSGSIZE);
  t_tx.resize(count);
  if (!copy_from_user(t_tx.data(), buf, count)) return fail(-EFAULT);
  const long r = backend()->spi_write(e.handle, t_tx);
  return r < 0 ? fail(r) : r;
}

}  // namespace

extern "C" {

void __chk_fail(void) __attribute__((noreturn));

__attribute__((visibility("default"))) int ioctl(int fd, unsigned long request, ...) noexcept {
  va_list ap;
  va_start(ap, request);
  void* arg = va_arg(ap, void*);
  va_end(ap);
  FdEntry* e = fd_entry(fd);
  if (!e || inside()) return real::ioctl(fd, request, arg);
  // The VFS answers these itself, before any driver sees them.
  if (request == FIOCLEX || request == FIONCLEX || request == FIONBIO || request == FIOASYNC)
    return real::ioctl(fd, request, arg);
  Guard guard;
  try {
    // Virtual time: reading a line's value in a loop is a busy wait like reading the clock.
    if (e->kind != HandleKind::spidev)
      if (VirtualHostTime* vt = installed_virtual_time()) vt->look();
    return static_cast<int>(emulated_ioctl(*e, request, arg));
  } catch (...) {
    errno = ENOMEM;
    return -1;
  }
}

__attribute__((visibility("default"))) ssize_t read(int fd, void* buf, size_t count) {
  FdEntry* e = fd_entry(fd);
  if (!e || inside()) {
    if (VirtualHostTime* vt = e ? nullptr : virtual_time()) {
      if (virtual_timerfds_exist()) {
        ssize_t r = 0;
        if (as_cancellation_point([&]() __attribute__((noinline)) { return read_virtual_timerfd(fd, buf, count, &r); }))
          return r;
      }
      // A pipe, socket or terminal: its wait for data is a covered wait (descriptor_wait.hpp).
      if (!readable_or_interrupted([&]() __attribute__((noinline)) { return covered_read_wait(*vt, fd, "read"); }))
        return -1;
    }
    return real::read(fd, buf, count);
  }
  auto body = [&]() __attribute__((noinline)) -> ssize_t {
    Guard guard;
    try {
      return emulated_read(fd, *e, buf, count);
    } catch (...) {
      errno = ENOMEM;
      return -1;
    }
  };
  // Virtual time: a read of gpio events may wait, a cancellation point acted on out here.
  if (installed_virtual_time()) return as_cancellation_point(body);
  return body();
}

__attribute__((visibility("default"))) ssize_t __read_chk(int fd, void* buf, size_t count, size_t buflen) {
  if (count > buflen) __chk_fail();
  return read(fd, buf, count);
}

__attribute__((visibility("default"))) ssize_t write(int fd, const void* buf, size_t count) {
  FdEntry* e = fd_entry(fd);
  if (!e || inside()) {
    ssize_t r = 0;
    if (!e && pwm_fds_exist() && !inside() && write_pwm_fd(fd, buf, count, r)) return r;
    return real::write(fd, buf, count);
  }
  Guard guard;
  try {
    return emulated_write(*e, buf, count);
  } catch (...) {
    errno = ENOMEM;
    return -1;
  }
}

// A sysfs attribute ignores the offset (pwm_sysfs.hpp); other files go to the C library.
__attribute__((visibility("default"))) ssize_t pwrite(int fd, const void* buf, size_t count, off_t offset) {
  ssize_t r = 0;
  if (pwm_fds_exist() && !inside() && write_pwm_fd(fd, buf, count, r)) return r;
  return syscall(SYS_pwrite64, fd, buf, count, offset);
}

__attribute__((visibility("default"))) ssize_t pwrite64(int fd, const void* buf, size_t count, off64_t offset) {
  ssize_t r = 0;
  if (pwm_fds_exist() && !inside() && write_pwm_fd(fd, buf, count, r)) return r;
  return syscall(SYS_pwrite64, fd, buf, count, offset);
}

}  // extern "C"
