#include "linux/kernel/uhid_cp2112.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <linux/uhid.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <thread>

#include "linux/kernel/cp2112_reports.hpp"

namespace l6470emu {

namespace {

struct HidBridge {
  int fd = -1;
  BridgeNode node;
  std::string uniq;  // HID_UNIQ, how the bridge's gpiochip is found in sysfs
  std::unique_ptr<Cp2112Reports> reports;
};

bool write_event(int fd, const uhid_event& ev) {
  for (;;) {
    const ssize_t n = write(fd, &ev, sizeof ev);
    if (n == static_cast<ssize_t>(sizeof ev)) return true;
    if (n < 0 && errno == EINTR) continue;
    return false;
  }
}

std::string read_text(const std::string& path) {
  std::ifstream f(path);
  std::string s((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  return s;
}

/// The /dev/gpiochipN whose HID parent carries HID_UNIQ=`uniq`, or "".
std::string find_gpiochip(const std::string& uniq) {
  DIR* d = opendir("/sys/bus/gpio/devices");
  if (!d) return "";
  std::string found;
  while (dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name.rfind("gpiochip", 0) != 0) continue;
    char target[4096];
    const std::string link = "/sys/bus/gpio/devices/" + name;
    const ssize_t n = readlink(link.c_str(), target, sizeof target - 1);
    if (n <= 0) continue;
    target[n] = 0;
    // .../0003:10C4:EA90.0001/gpiochip3: the parent's uevent names the HID device.
    std::string parent = "/sys/bus/gpio/devices/" + std::string(target);
    parent = parent.substr(0, parent.rfind('/'));
    if (read_text(parent + "/uevent").find("HID_UNIQ=" + uniq + "\n") != std::string::npos) {
      found = "/dev/" + name;
      break;
    }
  }
  closedir(d);
  return found;
}

}  // namespace

struct UhidGpioBridges::Impl {
  DeviceBoard& board;
  NodeAccess access;
  std::vector<HidBridge> bridges;
  std::vector<BridgeNode> nodes;
  int stop_fd = -1;
  std::thread thread;
  std::atomic<std::size_t> answered{0};

  Impl(DeviceBoard& b, NodeAccess a) : board(b), access(a) {}

  void handle(HidBridge& b) {
    uhid_event ev{};
    const ssize_t n = read(b.fd, &ev, sizeof ev);
    if (n <= 0) return;
    uhid_event reply{};
    switch (ev.type) {
      case UHID_GET_REPORT: {
        const std::vector<std::uint8_t> data = b.reports->get(ev.u.get_report.rnum);
        reply.type = UHID_GET_REPORT_REPLY;
        reply.u.get_report_reply.id = ev.u.get_report.id;
        reply.u.get_report_reply.err = data.empty() ? EIO : 0;
        reply.u.get_report_reply.size = static_cast<std::uint16_t>(data.size());
        std::memcpy(reply.u.get_report_reply.data, data.data(), data.size());
        write_event(b.fd, reply);
        ++answered;
        break;
      }
      case UHID_SET_REPORT: {
        const std::size_t size = std::min<std::size_t>(ev.u.set_report.size, UHID_DATA_MAX);
        reply.type = UHID_SET_REPORT_REPLY;
        reply.u.set_report_reply.id = ev.u.set_report.id;
        reply.u.set_report_reply.err = static_cast<std::uint16_t>(b.reports->set({ev.u.set_report.data, size}));
        write_event(b.fd, reply);
        ++answered;
        break;
      }
      case UHID_OUTPUT: {
        const std::size_t size = std::min<std::size_t>(ev.u.output.size, UHID_DATA_MAX);
        const std::vector<std::uint8_t> answer = b.reports->output({ev.u.output.data, size});
        if (!answer.empty()) {
          reply.type = UHID_INPUT2;
          reply.u.input2.size = static_cast<std::uint16_t>(answer.size());
          std::memcpy(reply.u.input2.data, answer.data(), answer.size());
          write_event(b.fd, reply);
        }
        break;
      }
      default:
        break;  // START, STOP, OPEN, CLOSE
    }
  }

  void loop() {
    std::vector<pollfd> fds;
    for (auto& b : bridges) fds.push_back({b.fd, POLLIN, 0});
    fds.push_back({stop_fd, POLLIN, 0});
    for (;;) {
      if (poll(fds.data(), fds.size(), -1) < 0) {
        if (errno == EINTR) continue;
        return;
      }
      if (fds.back().revents) return;
      for (std::size_t i = 0; i + 1 < fds.size(); ++i)
        if (fds[i].revents & POLLIN) handle(bridges[i]);
    }
  }
};

UhidGpioBridges::UhidGpioBridges(DeviceBoard& board, NodeAccess access) : impl_(std::make_unique<Impl>(board, access)) {}

UhidGpioBridges::~UhidGpioBridges() {
  Impl& impl = *impl_;
  // Destroyed while the thread still answers: the driver's removal may ask for reports.
  for (auto& b : impl.bridges) {
    uhid_event ev{};
    ev.type = UHID_DESTROY;
    write_event(b.fd, ev);
  }
  if (impl.thread.joinable()) {
    const std::uint64_t one = 1;
    (void)!write(impl.stop_fd, &one, sizeof one);
    impl.thread.join();
  }
  for (auto& b : impl.bridges) close(b.fd);
  if (impl.stop_fd >= 0) close(impl.stop_fd);
}

std::string UhidGpioBridges::start() {
  Impl& impl = *impl_;
  impl.stop_fd = eventfd(0, EFD_CLOEXEC);
  const std::vector<std::uint8_t> descriptor = Cp2112Reports::descriptor();
  const std::string run = std::to_string(getpid());
  for (std::size_t c = 0; c < impl.board.chain_count(); ++c) {
    const std::size_t chips = impl.board.chip_count(c);
    const std::string spidev = impl.board.nodes()[impl.board.spidev_node(c)].name;
    for (std::size_t k = 0; k < chips; ++k) {
      HidBridge b;
      b.fd = ::open("/dev/uhid", O_RDWR | O_CLOEXEC);
      if (b.fd < 0) {
        const int e = errno;
        return std::string("cannot open /dev/uhid (") + std::strerror(e) +
               (e == ENOENT ? "; load the module with modprobe uhid" : e == EACCES ? "; serving kernel nodes needs root" : "") +
               ")";
      }
      b.node = {c, k, ""};
      b.uniq = "l6470emu-" + run + "-" + spidev + "-" + std::to_string(k);
      DeviceBoard& board = impl.board;
      Cp2112Pins pins{[&board, c, k](Pin p) { return board.pin_level(c, k, p); },
                      [&board, c, k](Pin p, bool level) { board.drive_pin(c, k, p, level); }};
      // What users read (the HID name, the report label) numbers the chip as the board does;
      // phys and uniq keep the chain index, which never changes with the numbering.
      const std::size_t number = board.chip_numbering(c).number_of(k);
      b.reports = std::make_unique<Cp2112Reports>(pins, "L6470 chip " + std::to_string(number) + " of " + spidev, b.uniq);
      uhid_event ev{};
      ev.type = UHID_CREATE2;
      std::snprintf(reinterpret_cast<char*>(ev.u.create2.name), sizeof ev.u.create2.name, "l6470emu %s chip %zu",
                    spidev.c_str(), number);
      std::snprintf(reinterpret_cast<char*>(ev.u.create2.phys), sizeof ev.u.create2.phys, "l6470emu/%s/%zu",
                    spidev.c_str(), k);
      std::snprintf(reinterpret_cast<char*>(ev.u.create2.uniq), sizeof ev.u.create2.uniq, "%s", b.uniq.c_str());
      ev.u.create2.rd_size = static_cast<std::uint16_t>(descriptor.size());
      std::memcpy(ev.u.create2.rd_data, descriptor.data(), descriptor.size());
      ev.u.create2.bus = 0x03;  // BUS_USB
      ev.u.create2.vendor = kCp2112Vendor;
      ev.u.create2.product = kCp2112Product;
      if (!write_event(b.fd, ev)) {
        const int e = errno;
        close(b.fd);
        return std::string("cannot create a HID device through /dev/uhid (") + std::strerror(e) + ")";
      }
      impl.bridges.push_back(std::move(b));
    }
  }
  // The driver probes each bridge with reports: serve them before looking for the gpiochips.
  impl.thread = std::thread([&impl] { impl.loop(); });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (auto& b : impl.bridges) {
    while ((b.node.gpiochip = find_gpiochip(b.uniq)).empty() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    impl.nodes.push_back(b.node);
    if (b.node.gpiochip.empty())
      return "the kernel registered no gpiochip for " + impl.board.chip_numbering(b.node.chain).label(b.node.chip) + " of " +
             impl.board.nodes()[impl.board.spidev_node(b.node.chain)].name + " within 10 s (is the hid-cp2112 module loaded?)";
    for (int i = 0; i < 200; ++i) {
      struct stat st{};
      if (stat(b.node.gpiochip.c_str(), &st) == 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (chown(b.node.gpiochip.c_str(), impl.access.owner, impl.access.group) != 0 ||
        chmod(b.node.gpiochip.c_str(), impl.access.mode) != 0)
      return b.node.gpiochip + ": cannot set its owner and mode (" + std::strerror(errno) + ")";
  }
  return "";
}

const std::vector<BridgeNode>& UhidGpioBridges::nodes() const { return impl_->nodes; }

std::size_t UhidGpioBridges::reports_answered() const { return impl_->answered.load(); }

}  // namespace l6470emu
