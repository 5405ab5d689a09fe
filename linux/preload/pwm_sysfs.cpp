// The emulated /sys/class/pwm (pwm_sysfs.hpp) over Backend::pwm_write and pwm_read.
#include "linux/preload/pwm_sysfs.hpp"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <sys/stat.h>
#include <sys/syscall.h>

#include <atomic>
#include <memory>
#include <algorithm>
#include <charconv>
#include <cstring>
#include <mutex>
#include <unordered_map>

#include "linux/log.hpp"
#include "linux/preload/real.hpp"
#include "linux/preload/state.hpp"
#include "linux/preload/user_memory.hpp"

namespace l6470emu::preload {
namespace {

constexpr std::string_view kClassDir = "/sys/class/pwm";

// A path under /sys/class/pwm, taken apart.
struct PwmPath {
  enum class Kind { none, class_dir, chip_dir, channel_dir, attr } kind = Kind::none;
  std::size_t chain = 0;
  int channel = -1;  ///< -1: a chip's own file
  PwmAttr attr = PwmAttr::npwm;
};

// "pwmchip12" -> 12 (false for anything else: no sign, no leading zero).
bool number_after(std::string_view name, std::string_view prefix, std::size_t& out) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return false;
  name.remove_prefix(prefix.size());
  if (name.size() > 1 && name[0] == '0') return false;
  const auto [end, ec] = std::from_chars(name.data(), name.data() + name.size(), out);
  return ec == std::errc{} && end == name.data() + name.size();
}

Backend* pwm_backend() {
  Backend* b = backend();
  return b && b->pwm_chips() > 0 ? b : nullptr;
}

// Where `path` lies; Kind::none also for a chip or a channel the board lacks. A channel's
// directory and files exist while it is exported.
PwmPath parse(std::string_view path, Backend& b) {
  PwmPath p;
  while (path.size() > 1 && path.back() == '/') path.remove_suffix(1);
  if (path == kClassDir) {
    p.kind = PwmPath::Kind::class_dir;
    return p;
  }
  if (path.size() <= kClassDir.size() || path.compare(0, kClassDir.size(), kClassDir) != 0 ||
      path[kClassDir.size()] != '/')
    return p;
  std::string_view rest = path.substr(kClassDir.size() + 1);
  std::string_view parts[3];
  std::size_t n = 0;
  while (!rest.empty()) {
    if (n == 3) return p;
    const std::size_t slash = rest.find('/');
    parts[n++] = rest.substr(0, slash);
    rest = slash == std::string_view::npos ? std::string_view{} : rest.substr(slash + 1);
  }
  if (!number_after(parts[0], "pwmchip", p.chain) || p.chain >= b.pwm_chips()) return p;
  if (n == 1) {
    p.kind = PwmPath::Kind::chip_dir;
    return p;
  }
  if (n == 2) {
    if (const auto a = pwm_attr_named(parts[1], false)) {
      p.kind = PwmPath::Kind::attr;
      p.attr = *a;
      return p;
    }
  }
  std::size_t k = 0;
  if (!number_after(parts[1], "pwm", k) || k >= b.pwm_channels(p.chain)) return p;
  std::string probe;
  if (b.pwm_read(p.chain, static_cast<int>(k), PwmAttr::enable, probe) < 0) return p;  // not exported
  p.channel = static_cast<int>(k);
  if (n == 2) {
    p.kind = PwmPath::Kind::channel_dir;
    return p;
  }
  if (const auto a = pwm_attr_named(parts[2], true)) {
    p.kind = PwmPath::Kind::attr;
    p.attr = *a;
  }
  return p;
}

struct OpenAttr {
  std::size_t chain;
  int channel;
  PwmAttr attr;
  // Bytes of the memfd already taken (its contents at open, and what flush_pwm_fd passed on),
  // shared by the copies of the descriptor.
  std::shared_ptr<std::uint64_t> consumed;
};

std::mutex g_mutex;
std::unordered_map<int, OpenAttr>* g_fds = nullptr;  // never freed: used until exit
std::atomic<bool> g_any{false};

int fail(int e) {
  errno = e;
  return -1;
}

}  // namespace

VirtualPath lookup_pwm(std::string_view path) {
  VirtualPath v;
  Backend* b = pwm_backend();
  if (!b) return v;
  const PwmPath p = parse(path, *b);
  switch (p.kind) {
    case PwmPath::Kind::none:
      break;
    case PwmPath::Kind::class_dir:
      // The real one when the machine has it (its entries are listed with ours).
      if (real::access(std::string(kClassDir).c_str(), F_OK) != 0) v.type = VirtualPath::Type::directory;
      break;
    case PwmPath::Kind::chip_dir:
    case PwmPath::Kind::channel_dir:
      v.type = VirtualPath::Type::directory;
      break;
    case PwmPath::Kind::attr:
      v.type = VirtualPath::Type::file;
      v.mode = p.attr == PwmAttr::npwm ? 0444 : !pwm_attr_readable(p.attr) ? 0200 : 0644;
      break;
  }
  return v;
}

std::vector<std::pair<std::string, unsigned char>> pwm_dir_entries(std::string_view dir) {
  std::vector<std::pair<std::string, unsigned char>> out;
  Backend* b = pwm_backend();
  if (!b) return out;
  const PwmPath p = parse(dir, *b);
  if (p.kind == PwmPath::Kind::class_dir) {
    for (std::size_t c = 0; c < b->pwm_chips(); ++c) out.emplace_back("pwmchip" + std::to_string(c), DT_DIR);
  } else if (p.kind == PwmPath::Kind::chip_dir) {
    for (const char* f : {"npwm", "export", "unexport"}) out.emplace_back(f, DT_REG);
    std::string probe;
    for (std::size_t k = 0; k < b->pwm_channels(p.chain); ++k)
      if (b->pwm_read(p.chain, static_cast<int>(k), PwmAttr::enable, probe) == 0)
        out.emplace_back("pwm" + std::to_string(k), DT_DIR);
  } else if (p.kind == PwmPath::Kind::channel_dir) {
    for (const char* f : {"period", "duty_cycle", "enable", "polarity"}) out.emplace_back(f, DT_REG);
  }
  return out;
}

bool open_pwm_file(std::string_view path, int flags, int& fd) {
  if (path.size() < kClassDir.size() || path.compare(0, kClassDir.size(), kClassDir) != 0) return false;
  Backend* b = pwm_backend();
  if (!b) return false;
  const PwmPath p = parse(path, *b);
  if (p.kind != PwmPath::Kind::attr) return false;
  const int mode = flags & O_ACCMODE;
  const bool reads = mode == O_RDONLY || mode == O_RDWR;
  const bool writes = mode == O_WRONLY || mode == O_RDWR;
  if ((reads && !pwm_attr_readable(p.attr)) || (writes && !pwm_attr_writable(p.attr))) {
    fd = fail(EACCES);
    return true;
  }
  std::string content;
  if (reads)
    if (const long r = b->pwm_read(p.chain, p.channel, p.attr, content); r < 0) {
      fd = fail(static_cast<int>(-r));
      return true;
    }
  fd = memfd_create("l6470emu-pwm", (flags & O_CLOEXEC) ? MFD_CLOEXEC : 0);
  if (fd < 0) return true;
  raw_write_all(fd, content.data(), content.size());
  lseek(fd, 0, SEEK_SET);
  if (writes) {
    // memfd descriptors are read-write; the open's access mode decides what the program may do.
    std::lock_guard lock(g_mutex);
    if (!g_fds) g_fds = new std::unordered_map<int, OpenAttr>();
    (*g_fds)[fd] = OpenAttr{p.chain, p.channel, p.attr, std::make_shared<std::uint64_t>(content.size())};
    g_any.store(true, std::memory_order_release);
  }
  return true;
}

bool pwm_fds_exist() { return g_any.load(std::memory_order_acquire); }

bool write_pwm_fd(int fd, const void* buf, std::size_t count, ssize_t& result) {
  OpenAttr a{};
  {
    std::lock_guard lock(g_mutex);
    if (!g_fds) return false;
    const auto it = g_fds->find(fd);
    if (it == g_fds->end()) return false;
    a = it->second;
  }
  Guard guard;
  // sysfs takes at most a page less one byte per write.
  const std::size_t n = count < 4095 ? count : 4095;
  std::string text(n, '\0');
  if (!copy_from_user(text.data(), buf, n)) {
    result = fail(EFAULT);
    return true;
  }
  Backend* b = backend();
  const long r = b ? b->pwm_write(a.chain, a.channel, a.attr, text) : -ENODEV;
  result = r < 0 ? fail(static_cast<int>(-r)) : static_cast<ssize_t>(r);
  return true;
}

long flush_pwm_fd(int fd) {
  if (!pwm_fds_exist()) return 0;
  OpenAttr a{};
  std::string text;
  {
    std::lock_guard lock(g_mutex);
    if (!g_fds) return 0;
    const auto it = g_fds->find(fd);
    if (it == g_fds->end()) return 0;
    a = it->second;
    struct stat st {};
    if (::syscall(SYS_fstat, fd, &st) != 0 || static_cast<std::uint64_t>(st.st_size) <= *a.consumed) return 0;
    const std::uint64_t from = *a.consumed;
    text.resize(std::min<std::uint64_t>(static_cast<std::uint64_t>(st.st_size) - from, 4095));
    const long n = ::syscall(SYS_pread64, fd, text.data(), text.size(), static_cast<off_t>(from));
    *a.consumed = static_cast<std::uint64_t>(st.st_size);
    if (n <= 0) return 0;
    text.resize(static_cast<std::size_t>(n));
  }
  Guard guard;
  Backend* b = backend();
  const long r = b ? b->pwm_write(a.chain, a.channel, a.attr, text) : -ENODEV;
  if (r < 0) {
    std::string path = "/sys/class/pwm/pwmchip" + std::to_string(a.chain) + "/";
    if (a.channel >= 0) path += "pwm" + std::to_string(a.channel) + "/";
    log_line(path + pwm_attr_name(a.attr) + ": a write at close refused: " + std::strerror(static_cast<int>(-r)));
  }
  return r < 0 ? r : 0;
}

namespace {

// fopencookie's functions for a stream on a pwm attribute's descriptor.
ssize_t stream_read(void* cookie, char* buf, std::size_t n) {
  return ::syscall(SYS_read, static_cast<int>(reinterpret_cast<std::intptr_t>(cookie)), buf, n);
}
ssize_t stream_write(void* cookie, const char* buf, std::size_t n) {
  ssize_t r = 0;
  if (!write_pwm_fd(static_cast<int>(reinterpret_cast<std::intptr_t>(cookie)), buf, n, r)) return -1;
  return r < 0 ? 0 : r;  // 0: the C library's error for the stream (errno set)
}
int stream_close(void* cookie) { return close(static_cast<int>(reinterpret_cast<std::intptr_t>(cookie))); }

}  // namespace

FILE* pwm_stream(int fd, const char* mode) {
  {
    std::lock_guard lock(g_mutex);
    if (!g_fds || g_fds->find(fd) == g_fds->end()) return nullptr;
  }
  cookie_io_functions_t io{};
  io.read = stream_read;
  io.write = stream_write;
  io.close = stream_close;
  return fopencookie(reinterpret_cast<void*>(static_cast<std::intptr_t>(fd)), mode, io);
}

void forget_pwm_fd(int fd) {
  if (!pwm_fds_exist()) return;
  std::lock_guard lock(g_mutex);
  if (g_fds) g_fds->erase(fd);
}

void dup_pwm_fd(int from, int to) {
  if (!pwm_fds_exist() || from == to) return;
  std::lock_guard lock(g_mutex);
  if (!g_fds) return;
  const auto it = g_fds->find(from);
  if (it != g_fds->end())
    (*g_fds)[to] = it->second;
  else
    g_fds->erase(to);
}

}  // namespace l6470emu::preload
