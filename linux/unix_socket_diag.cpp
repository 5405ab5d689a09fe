// sock_diag's view of an AF_UNIX socket (linux/unix_socket_diag.hpp).
#include "linux/unix_socket_diag.hpp"

#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <linux/sock_diag.h>
#include <linux/unix_diag.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstring>

namespace l6470emu {

UnixSocketInfo unix_socket_info(unsigned long inode) {
  UnixSocketInfo info;
  const int s = socket(AF_NETLINK, SOCK_DGRAM | SOCK_CLOEXEC, NETLINK_SOCK_DIAG);
  if (s < 0) return info;
  struct {
    nlmsghdr header;
    unix_diag_req request;
  } ask{};
  ask.header.nlmsg_len = sizeof ask;
  ask.header.nlmsg_type = SOCK_DIAG_BY_FAMILY;
  ask.header.nlmsg_flags = NLM_F_REQUEST;
  ask.request.sdiag_family = AF_UNIX;
  ask.request.udiag_states = ~0u;
  ask.request.udiag_ino = static_cast<unsigned>(inode);
  ask.request.udiag_show = UDIAG_SHOW_PEER | UDIAG_SHOW_RQLEN;
  ask.request.udiag_cookie[0] = ask.request.udiag_cookie[1] = ~0u;  // INET_DIAG_NOCOOKIE: any
  sockaddr_nl kernel{};
  kernel.nl_family = AF_NETLINK;
  alignas(nlmsghdr) char reply[8192];
  if (sendto(s, &ask, sizeof ask, 0, reinterpret_cast<sockaddr*>(&kernel), sizeof kernel) == sizeof ask) {
    // A raw system call: the preload replaces recv(), and this runs inside it too.
    const long n = syscall(SYS_recvfrom, s, reply, sizeof reply, 0, nullptr, nullptr);
    const auto* h = reinterpret_cast<const nlmsghdr*>(reply);
    if (n > 0 && NLMSG_OK(h, static_cast<unsigned>(n)) && h->nlmsg_type == SOCK_DIAG_BY_FAMILY) {
      info.known = true;
      const auto* m = static_cast<const unix_diag_msg*>(NLMSG_DATA(h));
      int len = static_cast<int>(h->nlmsg_len - NLMSG_LENGTH(sizeof *m));
      for (auto* a = reinterpret_cast<const rtattr*>(m + 1); RTA_OK(a, len); a = RTA_NEXT(a, len)) {
        if (a->rta_type == UNIX_DIAG_PEER && RTA_PAYLOAD(a) >= sizeof(std::uint32_t)) {
          std::uint32_t p = 0;
          std::memcpy(&p, RTA_DATA(a), sizeof p);
          info.peer = p;
        } else if (a->rta_type == UNIX_DIAG_RQLEN && RTA_PAYLOAD(a) >= sizeof(unix_diag_rqlen)) {
          unix_diag_rqlen q{};
          std::memcpy(&q, RTA_DATA(a), sizeof q);
          info.receive_queue = q.udiag_rqueue;
        }
      }
    }
  }
  close(s);
  return info;
}

}  // namespace l6470emu
