// Where the transports' diagnostics go: stderr, nowhere, or a file; one line per call.
// Writes with the raw write(2) system call so a preloaded library never re-enters itself.
// A file that cannot be opened or written is said once on stderr, which takes the lines over.
#pragma once

#include <mutex>
#include <string>
#include <string_view>

namespace l6470emu {

/// A line-oriented diagnostic log ("stderr", "off" or a file path, appended to and created
/// if missing).
class DiagnosticLog {
 public:
  explicit DiagnosticLog(const std::string& where = "stderr");
  ~DiagnosticLog();
  DiagnosticLog(const DiagnosticLog&) = delete;
  DiagnosticLog& operator=(const DiagnosticLog&) = delete;

  /// Writes "l6470emu: <text>\n" (nothing when off). When the log file refuses a write (a full
  /// disk, /dev/full, a FIFO whose reader went away: never a SIGPIPE), one line says so on stderr
  /// with the file and the reason (once per file and process), the file is closed, and this line
  /// and every later one go to stderr.
  void line(std::string_view text);
  bool enabled() const { return fd_ >= 0; }
  /// Whether lines go to standard error ("stderr", or a file that could not be opened or written).
  bool to_stderr() const { return fd_ == 2; }
  /// The errno of opening the log file, 0 if it opened (or none was named). When it failed,
  /// one line said so on stderr at construction (once per file and process) and lines go to
  /// stderr instead: a host program is never stopped by its log.
  int open_error() const { return open_error_; }
  /// The errno of the first write the log file refused, 0 while none did (see line()).
  int write_error() const { return write_error_; }

 private:
  std::string where_;
  int fd_ = -1;
  bool owned_ = false;
  bool pipe_ = false;  // a FIFO or socket: a write may raise SIGPIPE
  int open_error_ = 0;
  int write_error_ = 0;
  std::mutex m_;
};

/// write(2) of the whole buffer through the raw system call, retrying on EINTR and short writes.
bool raw_write_all(int fd, const void* data, std::size_t size);

}  // namespace l6470emu
