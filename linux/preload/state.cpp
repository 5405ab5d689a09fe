// Preload state: configuration at load time, lazy backend, descriptor table, guard.
#include "linux/preload/state.hpp"

#include <pthread.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "linux/board_config_file.hpp"
#include "linux/log.hpp"
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

void atfork_prepare() {
  if (Backend* b = g_backend.load()) b->before_fork();
}
void atfork_parent() {
  if (Backend* b = g_backend.load()) b->after_fork_parent();
}
void atfork_child() {
  g_pid.store(getpid(), std::memory_order_release);
  if (Backend* b = g_backend.load()) b->after_fork_child();
}

// Runs when the library is loaded: a malformed config stops the program with one line.
__attribute__((constructor)) void load_config() {
  Guard guard;
  const char* socket = std::getenv("L6470EMU_SOCKET");
  const char* chain = std::getenv("L6470EMU_CHAIN");
  const char* file = std::getenv("L6470EMU_CONFIG");
  ParseResult parsed;
  if (chain && *chain) {
    parsed = parse_board_config(chain, "L6470EMU_CHAIN");
  } else if (file && *file) {
    parsed = load_board_config_file(file);
  } else if (socket && *socket) {
    parsed.config = BoardConfig{};
  } else {
    return;  // nothing configured: the library stays out of the way
  }
  if (!parsed.config) {
    std::string line = parsed.error.message + "\n";
    raw_write_all(2, line.data(), line.size());
    _exit(2);
  }
  g_config = new BoardConfig(std::move(*parsed.config));
  if (socket && *socket) g_config->socket = socket;
  if (const char* log = std::getenv("L6470EMU_LOG"); log && *log) g_config->log = log;
  if (const char* trace = std::getenv("L6470EMU_TRACE"); trace && *trace) g_config->trace = trace;
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

int node_index(const char* path) {
  if (!path || !active()) return -1;
  // Cheap filter first: only /dev/ and /sys/ paths can be ours.
  if (path[0] != '/' || (std::strncmp(path, "/dev/", 5) != 0)) return -1;
  const auto& n = nodes();
  for (std::size_t i = 0; i < n.size(); ++i)
    if (n[i].path == path) return static_cast<int>(i);
  return -1;
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
