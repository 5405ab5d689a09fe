#define FUSE_USE_VERSION 312
#include "linux/kernel/cuse_spidev.hpp"

#include <fcntl.h>
#include <fuse3/cuse_lowlevel.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/uio.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <thread>
#include <vector>

#include "linux/kernel/cuse_ioctl.hpp"

namespace l6470emu {

/// An open file of the node: the board's handle and the end of its socketpair the board gave
/// us (the kernel's file is the "copy" the handle lives for; closing our end releases it).
struct OpenFile {
  std::uint64_t handle = 0;
  int fd = -1;
};

struct CuseSpidev::Impl {
  DeviceBoard& board;
  std::size_t device;
  NodeAccess access;
  std::string devname;  // "DEVNAME=spidev0.0"
  fuse_session* session = nullptr;
  std::thread loop;
  std::mutex m;
  std::condition_variable cv;
  bool ready = false;
  unsigned major = 0, minor = 0;

  Impl(DeviceBoard& b, std::size_t d, NodeAccess a) : board(b), device(d), access(a) {}

  const DeviceNode& node() const { return board.nodes()[device]; }
};

namespace {

CuseSpidev::Impl& impl_of(fuse_req_t req) { return *static_cast<CuseSpidev::Impl*>(fuse_req_userdata(req)); }

OpenFile* file_of(fuse_file_info* fi) { return reinterpret_cast<OpenFile*>(static_cast<std::uintptr_t>(fi->fh)); }

void on_init_done(void* userdata) {
  auto& impl = *static_cast<CuseSpidev::Impl*>(userdata);
  std::lock_guard lock(impl.m);
  impl.ready = true;
  impl.cv.notify_all();
}

void on_open(fuse_req_t req, fuse_file_info* fi) {
  auto& impl = impl_of(req);
  const NewFile f = impl.board.open(impl.device, true);
  if (f.result < 0) {
    fuse_reply_err(req, static_cast<int>(-f.result));
    return;
  }
  auto* file = new OpenFile{f.handle, f.fd};
  fi->fh = reinterpret_cast<std::uintptr_t>(file);
  fi->direct_io = 1;
  fi->nonseekable = 1;
  if (fuse_reply_open(req, fi) != 0) {  // the opener is gone already
    close(file->fd);
    impl.board.closed(file->handle);
    delete file;
  }
}

void on_release(fuse_req_t req, fuse_file_info* fi) {
  auto& impl = impl_of(req);
  if (OpenFile* file = file_of(fi)) {
    close(file->fd);
    impl.board.closed(file->handle);
    delete file;
  }
  fuse_reply_err(req, 0);
}

void on_read(fuse_req_t req, size_t size, off_t, fuse_file_info* fi) {
  auto& impl = impl_of(req);
  std::vector<std::uint8_t> rx(size);
  const long r = impl.board.spi_read(file_of(fi)->handle, rx);
  if (r < 0) {
    fuse_reply_err(req, static_cast<int>(-r));
    return;
  }
  fuse_reply_buf(req, reinterpret_cast<const char*>(rx.data()), static_cast<std::size_t>(r));
}

void on_write(fuse_req_t req, const char* buf, size_t size, off_t, fuse_file_info* fi) {
  auto& impl = impl_of(req);
  const long r = impl.board.spi_write(file_of(fi)->handle, {reinterpret_cast<const std::uint8_t*>(buf), size});
  if (r < 0) {
    fuse_reply_err(req, static_cast<int>(-r));
    return;
  }
  fuse_reply_write(req, static_cast<std::size_t>(r));
}

void on_ioctl(fuse_req_t req, int cmd, void* arg, fuse_file_info* fi, unsigned flags, const void* in_buf,
              size_t in_bufsz, size_t out_bufsz) {
  auto& impl = impl_of(req);
  if (!(flags & FUSE_IOCTL_UNRESTRICTED)) {  // cannot happen with CUSE_UNRESTRICTED_IOCTL
    fuse_reply_err(req, ENOTTY);
    return;
  }
  // 32-bit callers (FUSE_IOCTL_COMPAT) pass the same command numbers and the same
  // spi_ioc_transfer layout (its pointers are __u64), so they need nothing special.
  const CuseIoctlStep step = spidev_cuse_ioctl(
      impl.board, file_of(fi)->handle, impl.node().bufsiz, static_cast<unsigned>(cmd),
      reinterpret_cast<std::uintptr_t>(arg), {static_cast<const std::uint8_t*>(in_buf), in_bufsz}, out_bufsz);
  if (step.retry) {
    std::vector<iovec> in(step.in.size()), out(step.out.size());
    for (std::size_t i = 0; i < in.size(); ++i)
      in[i] = {reinterpret_cast<void*>(static_cast<std::uintptr_t>(step.in[i].base)), step.in[i].len};
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = {reinterpret_cast<void*>(static_cast<std::uintptr_t>(step.out[i].base)), step.out[i].len};
    fuse_reply_ioctl_retry(req, in.data(), in.size(), out.data(), out.size());
    return;
  }
  if (step.result < 0) {
    fuse_reply_err(req, static_cast<int>(-step.result));
    return;
  }
  fuse_reply_ioctl(req, static_cast<int>(step.result), step.data.empty() ? nullptr : step.data.data(),
                   step.data.size());
}

const cuse_lowlevel_ops kOps = [] {
  cuse_lowlevel_ops ops{};
  ops.init_done = on_init_done;
  ops.open = on_open;
  ops.release = on_release;
  ops.read = on_read;
  ops.write = on_write;
  ops.ioctl = on_ioctl;
  return ops;
}();

}  // namespace

CuseSpidev::CuseSpidev(DeviceBoard& board, std::size_t device, NodeAccess access)
    : impl_(std::make_unique<Impl>(board, device, access)) {}

CuseSpidev::~CuseSpidev() {
  if (impl_->session) {
    // The loop's threads wait in read(/dev/cuse), which nothing short of process exit wakes: the
    // session is told to end and left to the kernel, which removes the node when the daemon's
    // descriptors close at exit. (The daemon destroys its nodes only when it is about to exit.)
    fuse_session_exit(impl_->session);
    impl_->loop.detach();
    // Still used by the detached threads until the process ends: parked where a leak checker sees
    // it held (by then the threads may have left the loop, and nothing else would point to it).
    static std::mutex parked_mutex;
    static auto* parked = new std::vector<Impl*>;
    std::lock_guard lock(parked_mutex);
    parked->push_back(impl_.release());
  }
}

std::string CuseSpidev::start() {
  Impl& impl = *impl_;
  const DeviceNode& node = impl.node();
  impl.devname = "DEVNAME=" + node.name;
  const char* dev_info[] = {impl.devname.c_str()};
  cuse_info ci{};
  ci.dev_major = 0;  // dynamic: 153 belongs to the kernel's spidev driver
  ci.dev_info_argc = 1;
  ci.dev_info_argv = dev_info;
  ci.flags = CUSE_UNRESTRICTED_IOCTL;
  const char* argv[] = {"l6470emu", nullptr};
  fuse_args args = FUSE_ARGS_INIT(1, const_cast<char**>(argv));
  impl.session = cuse_lowlevel_new(&args, &ci, &kOps, &impl);
  fuse_opt_free_args(&args);  // the session parsed them into a copy of its own (libfuse allocated it)
  if (!impl.session) return node.path + ": cannot create a CUSE session";
  const int fd = ::open("/dev/cuse", O_RDWR | O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    fuse_session_destroy(impl.session);
    impl.session = nullptr;
    return node.path + ": cannot open /dev/cuse (" + std::strerror(e) +
           (e == ENOENT ? "; load the module with modprobe cuse" : e == EACCES ? "; serving kernel nodes needs root" : "") +
           ")";
  }
  const std::string mountpoint = "/dev/fd/" + std::to_string(fd);
  if (fuse_session_mount(impl.session, mountpoint.c_str()) != 0) {
    close(fd);
    fuse_session_destroy(impl.session);
    impl.session = nullptr;
    return node.path + ": cannot attach to /dev/cuse";
  }
  impl.loop = std::thread([&impl] {
    fuse_loop_config* config = fuse_loop_cfg_create();
    fuse_loop_cfg_set_max_threads(config, 16);  // a message waits its bus time: others go on meanwhile
    fuse_session_loop_mt(impl.session, config);
    fuse_loop_cfg_destroy(config);
  });
  {
    std::unique_lock lock(impl.m);
    if (!impl.cv.wait_for(lock, std::chrono::seconds(10), [&] { return impl.ready; }))
      return node.path + ": the kernel did not accept the CUSE device within 10 s";
  }
  // devtmpfs makes the node as root:root 0600; give it the owner and mode asked for.
  for (int i = 0; i < 500; ++i) {
    struct stat st{};
    if (stat(node.path.c_str(), &st) == 0 && S_ISCHR(st.st_mode)) {
      impl.major = major(st.st_rdev);
      impl.minor = minor(st.st_rdev);
      if (chown(node.path.c_str(), impl.access.owner, impl.access.group) != 0 ||
          chmod(node.path.c_str(), impl.access.mode) != 0)
        return node.path + ": cannot set its owner and mode (" + std::strerror(errno) + ")";
      return "";
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return node.path + ": the CUSE device was registered but " + node.path + " did not appear (is devtmpfs mounted on /dev?)";
}

std::string CuseSpidev::device_number() const {
  return std::to_string(impl_->major) + ":" + std::to_string(impl_->minor);
}

}  // namespace l6470emu
