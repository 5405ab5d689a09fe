// The preload library's global state: configuration (read when the library is loaded),
// the backend (made on first use), the table of emulated file descriptors and the
// re-entrancy guard that sends the library's own calls straight to the C library.
#pragma once

#include <atomic>
#include <cstdint>
#include <string_view>

#include "linux/device_board.hpp"
#include "linux/preload/backend.hpp"

namespace l6470emu::preload {

/// What an emulated descriptor refers to. Shared by dup()ed descriptors (like a struct file).
struct FdEntry {
  std::uint64_t handle = 0;
  HandleKind kind = HandleKind::spidev;
  std::uint32_t node = 0;                ///< device node index (the gpiochip for line requests)
  std::atomic<std::uint32_t> record{0};  ///< bytes per read() record (events), 0 = not readable as records
  std::atomic<int> refs{1};
};

/// Whether the preload emulates anything at all in this process (a config was given).
bool active();
/// The backend, made on first call; nullptr when inactive.
Backend* backend();
/// Index of the device node at `path`, or -1 (also -1 when inactive).
int node_index(const char* path);
/// The device nodes (empty when inactive).
const std::vector<DeviceNode>& nodes();

/// The entry of `fd`, or nullptr for a descriptor the preload does not emulate.
FdEntry* fd_entry(int fd);
/// Records `entry` for `fd` (taking one reference).
void fd_store(int fd, FdEntry* entry);
/// Forgets `fd`; returns its entry with the table's reference handed to the caller, or nullptr.
FdEntry* fd_take(int fd);
/// Drops one reference; at zero tells the backend the descriptor is gone, and frees the entry.
void fd_release(FdEntry* entry);

/// Re-entrancy guard: while alive, the replaced functions pass straight through.
class Guard {
 public:
  Guard();
  ~Guard();
  Guard(const Guard&) = delete;
  Guard& operator=(const Guard&) = delete;
};
/// Whether the calling thread is inside the preload library already.
bool inside();
/// Whether this is a vfork()ed child running in its parent's memory before exec (posix_spawn,
/// CPython's subprocess): it must not change the parent's descriptor table. A system call:
/// ask only before changing the table.
bool in_vfork_child();

/// The daemon connection's descriptor: close() of it by the host is noticed.
void protect_fd(int fd);
bool protected_fd_is(int fd);
void real_close_protected(int fd);

/// Reports a line on the diagnostic log of this process (stderr unless log= says otherwise).
void log_line(std::string_view text);
/// Whether log_line() writes to standard error (also when the log is off: false).
bool log_is_stderr();

}  // namespace l6470emu::preload
