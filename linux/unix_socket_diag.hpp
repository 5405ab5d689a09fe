// What the kernel says of an AF_UNIX socket through sock_diag (NETLINK_SOCK_DIAG, as `ss -x`
// asks): its peer and the bytes waiting to be read. Used to tell whether anything outside a set
// of processes could still send to a socket pair. Linux only; no C library call the preload
// replaces (the reply is read with a raw system call).
#pragma once

#include <cstdint>

namespace l6470emu {

/// An AF_UNIX socket as sock_diag reports it.
struct UnixSocketInfo {
  bool known = false;              ///< the kernel answered for this inode
  unsigned long peer = 0;          ///< the connected peer's inode (0: none, or closed)
  std::uint32_t receive_queue = 0; ///< bytes (stream) or datagrams waiting to be read
};

/// Asks the kernel about the AF_UNIX socket with inode `inode` (known false when it cannot say:
/// no such socket, sock_diag unavailable).
UnixSocketInfo unix_socket_info(unsigned long inode);

}  // namespace l6470emu
