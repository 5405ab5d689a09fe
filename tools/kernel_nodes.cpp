#include "tools/kernel_nodes.hpp"

#include <grp.h>
#include <pwd.h>

#include <cerrno>
#include <charconv>
#include <vector>

#include "linux/device_board.hpp"
#include "linux/kernel/uhid_cp2112.hpp"

namespace l6470emu {

namespace {

bool parse_number(const std::string& s, unsigned long& v, int base = 10) {
  const char* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, v, base);
  return !s.empty() && ec == std::errc() && p == end;
}

}  // namespace

std::string parse_node_access(const std::string& owner, const std::string& group, const std::string& mode,
                              NodeAccess& access) {
  unsigned long v = 0;
  if (parse_number(owner, v)) {
    access.owner = static_cast<uid_t>(v);
  } else if (const passwd* pw = getpwnam(owner.c_str())) {
    access.owner = pw->pw_uid;
  } else {
    return "--node-owner " + owner + ": no such user";
  }
  if (parse_number(group, v)) {
    access.group = static_cast<gid_t>(v);
  } else if (const struct group* gr = getgrnam(group.c_str())) {
    access.group = gr->gr_gid;
  } else {
    return "--node-group " + group + ": no such group";
  }
  if (!parse_number(mode, v, 8) || v > 0777) return "--node-mode " + mode + ": not an octal mode from 0 to 0777";
  access.mode = static_cast<mode_t>(v);
  return "";
}

FrontEnds kernel_front_ends(bool cuse, bool uhid, NodeAccess access) {
  return [cuse, uhid, access](DeviceBoard& board, std::ostream& out, std::string& error) -> std::shared_ptr<void> {
    struct Kept {
      std::vector<std::unique_ptr<CuseSpidev>> spidevs;
      std::unique_ptr<UhidGpioBridges> bridges;
    };
    auto kept = std::make_shared<Kept>();
    if (cuse) {
      for (std::size_t c = 0; c < board.chain_count(); ++c) {
        auto dev = std::make_unique<CuseSpidev>(board, board.spidev_node(c), access);
        if (error = dev->start(); !error.empty()) return nullptr;
        out << "  kernel node " << board.nodes()[board.spidev_node(c)].path << " (CUSE, char " << dev->device_number()
            << ")\n";
        kept->spidevs.push_back(std::move(dev));
      }
    }
    if (uhid) {
      kept->bridges = std::make_unique<UhidGpioBridges>(board, access);
      if (error = kept->bridges->start(); !error.empty()) return nullptr;
      for (const auto& n : kept->bridges->nodes())
        out << "  kernel node " << n.gpiochip << " [cp2112_gpio] = " << board.chip_numbering(n.chain).label(n.chip) << " of "
            << board.nodes()[board.spidev_node(n.chain)].name << ": 0 BUSY, 1 FLAG, 2 SW, 3 STCK, 4 STBY_RST\n";
    }
    return kept;
  };
}

}  // namespace l6470emu
