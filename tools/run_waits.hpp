// `l6470emu run`'s view of a deadlock across the program's processes: each process under the
// preload publishes, while every thread of it waits and only another process could end a wait,
// what it waits on (linux/process_waits.hpp) in a directory run makes. When every live process of
// the run has done so, and each one's waits depend only on the others (a child that waits too, a
// pipe or a Unix socket pair only they hold, empty and with writers left), nothing can ever end
// any of them: a parent in waitpid() of a child that reads a pipe only the parent could write.
// Linux only (/proc, sock_diag).
#pragma once

#include <sys/types.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "linux/process_waits.hpp"

namespace l6470emu {

/// What run found: the processes and each one's waits in words (empty: no deadlock).
struct CrossProcessDeadlock {
  std::vector<pid_t> processes;     ///< every live process of the run
  std::vector<std::string> lines;   ///< "process 12 (name): thread 12 (name): waitpid() on ..., no timeout"
  bool found() const { return !processes.empty(); }
  bool operator==(const CrossProcessDeadlock&) const = default;
};

/// The run's waits directory (run_waits_directory of its report file): made empty at start,
/// removed with what is in it at the end.
class RunWaits {
 public:
  /// The directory for the run reporting to `report_path`; nullptr when it cannot be made (the
  /// run goes on without a view across processes: the wall-clock guard still ends it).
  static std::unique_ptr<RunWaits> make(const std::string& report_path);
  ~RunWaits();
  RunWaits(const RunWaits&) = delete;
  RunWaits& operator=(const RunWaits&) = delete;

  /// Looks once: whether every live descendant of this process (zombies aside) published its
  /// waits and each depends only on the others: a child among them, a pipe that only they hold
  /// and that is neither readable nor without writers as its waiter sees it, a Unix socket pair
  /// both of whose ends only they hold, with nothing queued; anything else (another socket, a
  /// process-shared object, a process that published nothing) is no deadlock.
  CrossProcessDeadlock look() const;
  /// The thread lines each process has published now, by pid (for the wall-clock guard's words).
  std::map<pid_t, std::vector<std::string>> said() const;

 private:
  explicit RunWaits(std::string dir) : dir_(std::move(dir)) {}
  std::map<pid_t, ProcessWaits> published() const;
  std::string dir_;
};

}  // namespace l6470emu
