// Trace files for the CLI: format detection on the first 64 KiB, sigrok-cli as a child
// process (posix_spawnp, stdout through a pipe, stderr to a temporary file).
#include "tools/trace_input.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <algorithm>
#include <map>
#include <sstream>
#include <stdexcept>

#include "daisychain/chain_spec.hpp"
#include "spi/trace_native.hpp"

extern char** environ;

namespace l6470emu {
namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw TraceError(path, 0, std::string("cannot open: ") + std::strerror(errno));
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw TraceError(path, 0, "read error");
  return s.str();
}

std::string read_head(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw TraceError(path, 0, std::string("cannot open: ") + std::strerror(errno));
  std::string head(64 * 1024, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

TraceFormat format_of(const std::string& path, const TraceInputOptions& options) {
  if (options.format != TraceFormat::unknown) return options.format;
  const TraceFormat f = detect_trace_format(read_head(path), path);
  if (f == TraceFormat::unknown)
    throw TraceError(path, 0,
                     "unknown trace format (native, Saleae CSV, umockdev .ioctl, ftrace text, sigrok JSON trace, VCD "
                     "or .sr; --format names it)");
  return f;
}

}  // namespace

std::string run_sigrok_spi_decoder(const std::string& path, const TraceInputOptions& options) {
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

  int out_pipe[2];
  if (pipe(out_pipe) != 0) throw TraceError(path, 0, std::string("pipe: ") + std::strerror(errno));
  char err_path[] = "/tmp/l6470emu-sigrok-XXXXXX";
  const int err_fd = mkstemp(err_path);
  if (err_fd < 0) throw TraceError(path, 0, std::string("mkstemp: ") + std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out_pipe[1], 1);
  posix_spawn_file_actions_adddup2(&actions, err_fd, 2);
  posix_spawn_file_actions_addclose(&actions, out_pipe[0]);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(out_pipe[1]);
  std::string out;
  if (rc == 0) {
    char buf[1 << 16];
    for (;;) {
      const ssize_t got = read(out_pipe[0], buf, sizeof buf);
      if (got > 0) out.append(buf, static_cast<std::size_t>(got));
      else if (got == 0 || errno != EINTR) break;
    }
  }
  close(out_pipe[0]);
  int status = 0;
  if (rc == 0) waitpid(pid, &status, 0);
  std::string err;
  {
    std::ifstream e(err_path);
    std::getline(e, err);
  }
  close(err_fd);
  unlink(err_path);
  if (rc != 0)
    throw TraceError(path, 0, "cannot run " + options.sigrok_cli + " (" + std::strerror(rc) +
                                  "): install the sigrok-cli package to read logic captures");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw TraceError(path, 0, "sigrok-cli failed" + (err.empty() ? std::string() : ": " + err));
  if (out.empty()) throw TraceError(path, 0, "sigrok-cli decoded nothing (check the channel names: --sigrok-decoder)");
  return out;
}

TraceFile::TraceFile(std::string path, const TraceInputOptions& options)
    : path_(std::move(path)), format_(format_of(path_, options)) {
  if (format_ == TraceFormat::native) {
    header_ = NativeTraceReader(path_).header();
    return;
  }
  if (format_ == TraceFormat::vcd) {
    trace_ = import_sigrok_json(run_sigrok_spi_decoder(path_, options), path_, options.import);
    trace_.header.format = "sigrok-cli on a logic capture";
  } else {
    trace_ = import_trace(read_file(path_), path_, format_, options.import);
  }
  header_ = trace_.header;
}

std::unique_ptr<TraceReader> TraceFile::read() const {
  if (format_ == TraceFormat::native) return std::make_unique<NativeTraceReader>(path_);
  return trace_.reader();
}

Trace TraceFile::load() const {
  if (format_ != TraceFormat::native) return trace_;
  Trace t;
  NativeTraceReader r(path_);
  t.header = r.header();
  TraceEvent e;
  while (r.next(e)) t.write(e);
  return t;
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
