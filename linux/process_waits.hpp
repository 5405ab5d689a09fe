// What a process of `l6470emu run` publishes while every thread of it waits and only another
// process could wake one (a child it waits for, a pipe another process holds): its file in the
// run's waits directory. run reads them to see a deadlock across processes (tools/run_waits.hpp).
// The format only, shared by the preload that writes it and run that reads it; no /proc here.
#pragma once

#include <sys/types.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace l6470emu {

/// The directory the processes of a run publish their waits in, one file per process named by
/// its pid: beside the run's report file (kRunReportEnv), made by `l6470emu run` (when it does not
/// exist, nothing is published).
std::string run_waits_directory(const std::string& report_path);

/// One thing outside the process that could end one of its waits.
struct WaitDependency {
  enum class Kind : unsigned char {
    child,  ///< a child process (`pid`) a thread waits for (waitpid and its kin)
    pipe,   ///< a pipe (`inode`) other processes hold, waited on through descriptor `fd`
    socket, ///< a connected AF_UNIX socket (`inode`, its peer `peer`) other processes hold
    other,  ///< anything else (a socket, a process-shared semaphore, a FIFO): never a deadlock
  };
  Kind kind = Kind::other;
  pid_t pid = 0;
  unsigned long inode = 0;
  unsigned long peer = 0;
  int fd = -1;
  bool operator==(const WaitDependency&) const = default;
};

/// A process's published waits: what could end them, and each thread's wait in words.
struct ProcessWaits {
  std::vector<WaitDependency> dependencies;
  std::vector<std::string> threads;  ///< "thread 12 (name): waitpid(), no timeout", one a line
  bool operator==(const ProcessWaits&) const = default;
};

/// The file's text: one line per dependency ("child 123", "pipe 4567 5", "socket 4568 4569 6",
/// "other"), then one "| "-prefixed line per thread.
std::string format_process_waits(const ProcessWaits& waits);
/// The file's text back; nullopt when a line is not one format_process_waits writes.
std::optional<ProcessWaits> parse_process_waits(std::string_view text);

}  // namespace l6470emu
