// Trace files for the CLI: format detection on the first 64 KiB, sigrok-cli as a child
// process (fork/exec, stdout through a pipe, stderr to a temporary file, a time limit, and
// killed with us).
#include "tools/trace_input.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <algorithm>
#include <map>
#include <sstream>
#include <new>
#include <stdexcept>

#include "daisychain/chain_spec.hpp"
#include "spi/trace_file.hpp"
#include "spi/trace_native.hpp"
#include "tools/progress.hpp"

namespace l6470emu {
namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

TraceFormat format_of(const std::string& path, const TraceInputOptions& options) {
  if (options.format != TraceFormat::unknown) return options.format;
  const std::string head = read_trace_file_head(path, 64 * 1024);
  if (head.empty() && !ends_with(path, ".sr"))
    throw TraceError(path, 0, "empty file (no trace in it: a capture that was never written, or cut to nothing)");
  const TraceFormat f = detect_trace_format(head, without_gz(path));
  if (f == TraceFormat::unknown)
    throw TraceError(path, 0,
                     "unknown trace format (native, Saleae CSV, umockdev .ioctl, ftrace text, sigrok JSON trace, VCD "
                     "or .sr; --format names it)");
  return f;
}

}  // namespace

static std::chrono::seconds sigrok_time_limit(const std::string& path, const TraceInputOptions& options) {
  if (options.sigrok_time_limit.count() > 0) return options.sigrok_time_limit;
  // sigrok-cli decodes a VCD at roughly 1 MB/s on a slow machine: 1 s per 100 kB leaves room,
  // and no capture gets less than 30 s.
  struct stat st {};
  const std::uintmax_t size = ::stat(path.c_str(), &st) == 0 && st.st_size > 0 ? static_cast<std::uintmax_t>(st.st_size) : 0;
  return std::chrono::seconds(std::max<std::uintmax_t>(30, size / 100'000));
}

namespace {

// Runs sigrok-cli's spi decoder and hands its standard output to `sink` as it comes; returns how
// many bytes it wrote.
std::uint64_t run_sigrok(const std::string& path, const TraceInputOptions& options,
                         const std::function<void(const char*, std::size_t)>& sink) {
  std::vector<std::string> args = {options.sigrok_cli};
  if (!ends_with(path, ".sr")) {
    args.push_back("-I");
    args.push_back("vcd");
  }
  args.insert(args.end(), {"-i", path, "-P", options.sigrok_decoder, "-A",
                           "spi=mosi-transfer:miso-transfer:mosi-data:miso-data", "--protocol-decoder-jsontrace"});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const auto limit = sigrok_time_limit(path, options);

  int out_pipe[2];
  if (pipe2(out_pipe, O_CLOEXEC) != 0) throw TraceError(path, 0, std::string("pipe: ") + std::strerror(errno));
  char err_path[] = "/tmp/l6470emu-sigrok-XXXXXX";
  const int err_fd = mkostemp(err_path, O_CLOEXEC);
  if (err_fd < 0) {
    close(out_pipe[0]);
    close(out_pipe[1]);
    throw TraceError(path, 0, std::string("mkstemp: ") + std::strerror(errno));
  }
  // A pipe that reports whether exec failed (it closes on a successful exec).
  int exec_pipe[2];
  if (pipe2(exec_pipe, O_CLOEXEC) != 0) {
    close(out_pipe[0]);
    close(out_pipe[1]);
    close(err_fd);
    unlink(err_path);
    throw TraceError(path, 0, std::string("pipe: ") + std::strerror(errno));
  }
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {
    // The child: only async-signal-safe calls until exec. sigrok-cli dies with us (SIGKILL of
    // l6470emu must not leave it running), and gets our stdout pipe and the stderr file.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);  // the parent died before prctl
    dup2(out_pipe[1], 1);
    dup2(err_fd, 2);
    execvp(argv[0], argv.data());
    const int e = errno;
    [[maybe_unused]] const ssize_t n = write(exec_pipe[1], &e, sizeof e);
    _exit(127);
  }
  const int fork_errno = errno;
  close(out_pipe[1]);
  close(exec_pipe[1]);
  auto cleanup = [&] {
    close(out_pipe[0]);
    close(exec_pipe[0]);
    close(err_fd);
    unlink(err_path);
  };
  if (pid < 0) {
    cleanup();
    throw TraceError(path, 0, std::string("fork: ") + std::strerror(fork_errno));
  }
  int exec_errno = 0;
  if (read(exec_pipe[0], &exec_errno, sizeof exec_errno) == static_cast<ssize_t>(sizeof exec_errno)) {
    waitpid(pid, nullptr, 0);
    cleanup();
    throw TraceError(path, 0, "cannot run " + options.sigrok_cli + " (" + std::strerror(exec_errno) +
                                  "): install the sigrok-cli package to read logic captures");
  }

  // Its output, until it closes stdout or the time limit passes.
  std::uint64_t out_bytes = 0;
  std::string sink_error;
  const auto deadline = std::chrono::steady_clock::now() + limit;
  bool timed_out = false;
  char buf[1 << 16];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{out_pipe[0], POLLIN, 0};
    const int r = poll(&p, 1, static_cast<int>(std::min<std::int64_t>(left.count(), 1000)));
    if (r < 0 && errno != EINTR) break;
    if (r <= 0) continue;
    const ssize_t got = read(out_pipe[0], buf, sizeof buf);
    if (got > 0) {
      try {
        sink(buf, static_cast<std::size_t>(got));
      } catch (const std::exception& e) {
        sink_error = e.what();
        kill(pid, SIGKILL);
        break;
      }
      out_bytes += static_cast<std::uint64_t>(got);
    } else if (got == 0 || errno != EINTR) {
      break;
    }
  }
  if (timed_out) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  std::string err;
  {
    std::ifstream e(err_path);
    std::getline(e, err);
  }
  cleanup();
  if (!sink_error.empty()) throw TraceError(path, 0, "sigrok-cli's output could not be kept: " + sink_error);
  if (timed_out)
    throw TraceError(path, 0, "sigrok-cli did not finish within " + std::to_string(limit.count()) +
                                  " s and was stopped (a malformed capture, or one too long: cut it, or give "
                                  "-I vcd:compress=N to sigrok-cli yourself)");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw TraceError(path, 0, "sigrok-cli failed" + (err.empty() ? std::string() : ": " + err));
  if (out_bytes == 0) throw TraceError(path, 0, "sigrok-cli decoded nothing (check the channel names: --sigrok-decoder)");
  return out_bytes;
}

// A temporary file removed when this goes away.
class TempFile {
 public:
  TempFile() {
    char name[] = "/tmp/l6470emu-sigrok-json-XXXXXX";
    fd_ = mkostemp(name, O_CLOEXEC);
    if (fd_ < 0) throw std::runtime_error(std::string("mkstemp: ") + std::strerror(errno));
    path_ = name;
  }
  ~TempFile() {
    if (fd_ >= 0) close(fd_);
    unlink(path_.c_str());
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  const std::string& path() const { return path_; }
  void write_all(const char* data, std::size_t size) {
    while (size > 0) {
      const ssize_t n = ::write(fd_, data, size);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw std::runtime_error(path_ + ": write failed: " + std::strerror(n < 0 ? errno : EIO));
      data += n;
      size -= static_cast<std::size_t>(n);
    }
  }

 private:
  int fd_ = -1;
  std::string path_;
};

}  // namespace

std::string run_sigrok_spi_decoder(const std::string& path, const TraceInputOptions& options) {
  std::string out;
  run_sigrok(path, options, [&](const char* data, std::size_t size) { out.append(data, size); });
  return out;
}

TraceFile::TraceFile(std::string path, const TraceInputOptions& options)
    : path_(std::move(path)), format_(format_of(path_, options)), max_frames_(options.import.max_frames) {
  try {
    open(options);
  } catch (const std::bad_alloc&) {
    throw TraceError(path_, 0, out_of_memory());
  }
}

std::string TraceFile::out_of_memory() const {
  return "out of memory while reading it (an imported trace takes about 70 bytes a frame plus 3 a byte: a lower "
         "--max-frames than " + std::to_string(max_frames_) + " refuses it sooner)";
}

void TraceFile::open(const TraceInputOptions& options) {
  if (format_ == TraceFormat::native) {
    header_ = NativeTraceReader(path_, max_frames_).header();
    return;
  }
  // Reading a large capture takes a while: a bar on a terminal.
  ProgressBar bar = ProgressBar::on_stderr("reading " + path_);
  ImportOptions import = options.import;
  import.progress = [&bar](const ReadProgress& p) { bar.update(p.done, p.total, p.bytes ? "bytes" : "events"); };
  if (format_ == TraceFormat::vcd) {
    if (TraceFileReader(path_).gzip())
      throw TraceError(path_, 0, "a gzip-compressed logic capture: sigrok-cli reads it uncompressed (gunzip it first)");
    // sigrok-cli's output goes to a file and is read from there a piece at a time (a long
    // capture's JSON is many times its size).
    TempFile json;
    run_sigrok(path_, options, [&json](const char* data, std::size_t size) { json.write_all(data, size); });
    try {
      trace_ = import_trace_file(json.path(), TraceFormat::sigrok, import);
    } catch (const TraceError& e) {
      // Named after the capture: the JSON was ours.
      throw TraceError(path_, e.line(), e.reason());
    }
    trace_.header.name = path_;
    trace_.header.format = "sigrok-cli on a logic capture";
  } else {
    trace_ = import_trace_file(path_, format_, import);
  }
  bar.finish();
  header_ = trace_.header;
}

std::unique_ptr<TraceReader> TraceFile::read() const {
  if (format_ == TraceFormat::native) return std::make_unique<NativeTraceReader>(path_, max_frames_);
  return trace_.reader();
}

Trace TraceFile::load() const {
  try {
    if (format_ != TraceFormat::native) return trace_;
    Trace t;
    NativeTraceReader r(path_, max_frames_);
    t.header = r.header();
    TraceEvent e;
    while (r.next(e)) t.write(e);
    return t;
  } catch (const std::bad_alloc&) {
    throw TraceError(path_, 0, out_of_memory());
  }
}

std::vector<const Variant*> chain_for_trace(const std::string& spec, const TraceFile& file, std::string& how) {
  auto parse = [&](const std::string& text, std::uint64_t line, const std::string& from) {
    try {
      return parse_chain_spec(text);
    } catch (const std::invalid_argument& e) {
      throw TraceError(from, line, e.what());
    }
  };
  if (!spec.empty()) {
    how = "from --chain";
    return parse(spec, 0, "--chain");
  }
  const TraceHeader& h = file.header();
  if (!h.chain.empty()) {
    how = "from the trace";
    return parse(h.chain, h.chain_line, file.path());
  }
  std::map<std::size_t, std::uint64_t> lengths;
  std::unique_ptr<TraceReader> reader = file.read();
  TraceEvent e;
  std::uint64_t frames = 0;
  while (frames < 10000 && reader->next(e))
    if (e.kind == TraceEventKind::frame && !e.mosi.empty()) {
      ++lengths[e.mosi.size()];
      ++frames;
    }
  std::size_t best = 1;
  std::uint64_t count = 0;
  for (const auto& [len, c] : lengths)
    if (c > count) {
      best = len;
      count = c;
    }
  best = std::min<std::size_t>(best, 256);
  how = "guessed from the most common frame length; --chain sets it";
  return std::vector<const Variant*>(best, &l6470());
}

}  // namespace l6470emu
