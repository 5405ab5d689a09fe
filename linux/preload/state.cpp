// Preload state: configuration at load time, lazy backend, descriptor table, guard.
#include "linux/preload/fork_server.hpp"
#include "linux/preload/state.hpp"

#include <pthread.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "board/coverage_file.hpp"
#include "board/environment_names.hpp"
#include "linux/board_config_file.hpp"
#include "linux/device_paths.hpp"
#include "linux/log.hpp"
#include "linux/preload/check_exit.hpp"
#include "linux/preload/coverage.hpp"
#include "linux/preload/real.hpp"

namespace l6470emu::preload {
namespace {

thread_local int t_depth __attribute__((tls_model("initial-exec"))) = 0;

std::atomic<bool> g_active{false};
BoardConfig* g_config = nullptr;       // set once by the constructor, never freed
std::mutex g_backend_mutex;
std::atomic<Backend*> g_backend{nullptr};
std::atomic<int> g_protected_fd{-1};
DiagnosticLog* g_log = nullptr;

constexpr int kTableSize = 1 << 16;
std::atomic<FdEntry*> g_table[kTableSize];
std::mutex g_overflow_mutex;
std::unordered_map<int, FdEntry*>* g_overflow = nullptr;
std::atomic<bool> g_overflow_used{false};

const std::vector<DeviceNode> kNoNodes;

// The process the descriptor table belongs to: a vfork()ed child runs in its parent's memory
// until it execs (fork() handlers do not run for it), and must leave the table alone.
std::atomic<pid_t> g_pid{0};

// A snapshot's fork (fork_server.cpp) holds the scheduler's lock already, in a process of one
// thread, and its child keeps the board as it is: the backend's handlers are not for it.
void atfork_prepare() {
  if (snapshot_forking()) return;
  if (Backend* b = g_backend.load()) b->before_fork();
}
void atfork_parent() {
  if (snapshot_forking()) return;
  if (Backend* b = g_backend.load()) b->after_fork_parent();
}
void atfork_child() {
  g_pid.store(getpid(), std::memory_order_release);
  if (snapshot_forking()) return;
  if (Backend* b = g_backend.load()) b->after_fork_child();
}

[[noreturn]] void config_error(const std::string& message) {
  const std::string line = message + "\n";
  raw_write_all(2, line.data(), line.size());
  _exit(2);
}

// Runs when the library is loaded: a malformed config stops the program with one line; a
// mistyped L6470EMU_* variable gets a warning even when it leaves nothing configured.
__attribute__((constructor)) void load_config() {
  Guard guard;
  if (const std::string unknown = unknown_environment_variables(
          environ, "the preload reads L6470EMU_CHAIN, _CONFIG, _SOCKET, _LOG, _TRACE, _SHM, _CHECK, _CHECK_ALLOW, _COVERAGE");
      !unknown.empty())
    raw_write_all(2, unknown.data(), unknown.size());
  const char* socket = std::getenv("L6470EMU_SOCKET");
  const char* chain = std::getenv("L6470EMU_CHAIN");
  const char* file = std::getenv("L6470EMU_CONFIG");
  ParseResult parsed;
  std::string origin;
  if (chain && *chain) {
    origin = "L6470EMU_CHAIN";
    parsed = parse_board_config(chain, origin);
  } else if (file && *file) {
    origin = file;
    parsed = load_board_config_file(file);
  } else if (socket && *socket) {
    parsed.config = BoardConfig{};
  } else {
    return;  // nothing configured: the library stays out of the way
  }
  if (const std::string why = check_coverage_environment(); !why.empty()) config_error(why);
  // A node path this machine already uses for something else would be taken over: refused too.
  if (parsed.config) parsed.error.message = check_device_paths(*parsed.config, origin);
  if (!parsed.config || !parsed.error.message.empty()) config_error(parsed.error.message);
  g_config = new BoardConfig(std::move(*parsed.config));
  if (socket && *socket) g_config->socket = socket;
  if (const char* log = std::getenv("L6470EMU_LOG"); log && *log) g_config->log = log;
  if (const char* trace = std::getenv("L6470EMU_TRACE"); trace && *trace) g_config->trace = trace;
  if (const char* check = std::getenv("L6470EMU_CHECK"); check && *check) {
    std::string why;
    const auto level = parse_check_level(check, why);
    if (!level) config_error("l6470emu: L6470EMU_CHECK " + why);
    g_config->check.level = *level;
  }
  if (const char* allow = std::getenv("L6470EMU_CHECK_ALLOW"); allow && *allow) {
    std::string why;
    const auto rules = parse_rule_list(allow, why);
    if (!rules) config_error("l6470emu: L6470EMU_CHECK_ALLOW " + why);
    g_config->check.allowed = *rules;
  }
  // Virtual host time is in process only: with a daemon the program's clock stays real.
  if (g_config->time.virtual_time && !g_config->socket.empty())
    config_error(std::string("l6470emu: time=virtual runs the board inside the program, but ") +
                 (socket && *socket ? "L6470EMU_SOCKET" : "socket=") + " sends it to the daemon at " +
                 g_config->socket +
                 ": drop one (the daemon's clock is virtual with `serve --virtual-time`, moved by bus time and `ctl advance`)");
  g_log = new DiagnosticLog(g_config->log);
  g_pid.store(getpid(), std::memory_order_release);
  pthread_atfork(atfork_prepare, atfork_parent, atfork_child);
  g_active.store(true, std::memory_order_release);
  // Virtual time is the program's clock from its start, not from its first open of a device.
  if (g_config->time.virtual_time && g_config->socket.empty()) backend();
}

}  // namespace

Guard::Guard() { ++t_depth; }
Guard::~Guard() { --t_depth; }
bool inside() { return t_depth > 0; }

bool in_vfork_child() {
  const pid_t owner = g_pid.load(std::memory_order_acquire);
  return owner != 0 && getpid() != owner;
}

bool active() { return g_active.load(std::memory_order_acquire); }

Backend* backend() {
  if (!active()) return nullptr;
  Backend* b = g_backend.load(std::memory_order_acquire);
  if (b) return b;
  Guard guard;
  std::lock_guard lock(g_backend_mutex);
  b = g_backend.load(std::memory_order_acquire);
  if (b) return b;
  try {
    std::unique_ptr<Backend> made = g_config->socket.empty() ? make_local_backend(*g_config)
                                                             : make_remote_backend(g_config->socket, g_config->log);
    if (!g_config->socket.empty() && !g_config->trace.empty())
      log_line("trace= / L6470EMU_TRACE is ignored with a daemon: record with `serve --record` or `ctl trace start`");
    if (!g_config->socket.empty() && std::getenv(kCoverageEnv))
      log_line("L6470EMU_COVERAGE is ignored with a daemon: the daemon collects coverage (serve --coverage FILE)");
    if (!g_config->socket.empty() && (std::getenv("L6470EMU_CHECK") || std::getenv("L6470EMU_CHECK_ALLOW")))
      log_line("L6470EMU_CHECK / L6470EMU_CHECK_ALLOW are ignored with a daemon: its board checks as its description "
               "says (serve --chain \"... check=error\")");
    b = made.release();
  } catch (const std::exception& e) {
    log_line(std::string("cannot start the emulator: ") + e.what());
    g_active.store(false);
    return nullptr;
  } catch (...) {
    g_active.store(false);
    return nullptr;
  }
  g_backend.store(b, std::memory_order_release);
  return b;
}

const std::vector<DeviceNode>& nodes() {
  Backend* b = backend();
  return b ? b->nodes() : kNoNodes;
}

FdEntry* fd_entry(int fd) {
  if (fd < 0) return nullptr;
  if (fd < kTableSize) return g_table[fd].load(std::memory_order_acquire);
  if (!g_overflow_used.load(std::memory_order_acquire)) return nullptr;
  std::lock_guard lock(g_overflow_mutex);
  auto it = g_overflow->find(fd);
  return it == g_overflow->end() ? nullptr : it->second;
}

void fd_store(int fd, FdEntry* entry) {
  if (fd < 0) return;
  if (fd < kTableSize) {
    FdEntry* old = g_table[fd].exchange(entry, std::memory_order_acq_rel);
    if (old) fd_release(old);
    return;
  }
  std::lock_guard lock(g_overflow_mutex);
  if (!g_overflow) g_overflow = new std::unordered_map<int, FdEntry*>();
  FdEntry*& slot = (*g_overflow)[fd];
  if (slot) fd_release(slot);
  slot = entry;
  g_overflow_used.store(true, std::memory_order_release);
}

FdEntry* fd_take(int fd) {
  if (fd < 0) return nullptr;
  if (fd < kTableSize) {
    if (!g_table[fd].load(std::memory_order_relaxed)) return nullptr;
    return g_table[fd].exchange(nullptr, std::memory_order_acq_rel);
  }
  if (!g_overflow_used.load(std::memory_order_acquire)) return nullptr;
  std::lock_guard lock(g_overflow_mutex);
  auto it = g_overflow->find(fd);
  if (it == g_overflow->end()) return nullptr;
  FdEntry* e = it->second;
  g_overflow->erase(it);
  return e;
}

void fd_release(FdEntry* entry) {
  if (!entry) return;
  if (entry->refs.fetch_sub(1, std::memory_order_acq_rel) != 1) return;
  if (Backend* b = g_backend.load(std::memory_order_acquire)) {
    Guard guard;
    try {
      b->closed(entry->handle);
    } catch (...) {
    }
  }
  delete entry;
}

void protect_fd(int fd) { g_protected_fd.store(fd); }
bool protected_fd_is(int fd) { return fd >= 0 && g_protected_fd.load() == fd; }
void real_close_protected(int fd) {
  int expected = fd;
  g_protected_fd.compare_exchange_strong(expected, -1);
  real::close(fd);
}

void log_line(std::string_view text) {
  if (g_log) g_log->line(text);
}

bool log_is_stderr() { return g_log && g_log->to_stderr(); }

}  // namespace l6470emu::preload
