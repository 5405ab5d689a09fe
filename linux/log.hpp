// Where the transports' diagnostics go: stderr, nowhere, or a file; one line per call.
// Writes with the raw write(2) system call so a preloaded library never re-enters itself.
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

  /// Writes "l6470emu: <text>\n" (nothing when off).
  void line(std::string_view text);
  bool enabled() const { return fd_ >= 0; }
  /// The errno of opening the log file, 0 if it opened (or none was named). When it failed,
  /// one line said so on stderr at construction (once per file and process) and lines go to
  /// stderr instead: a host program is never stopped by its log.
  int open_error() const { return open_error_; }

 private:
  int fd_ = -1;
  bool owned_ = false;
  int open_error_ = 0;
  std::mutex m_;
};

/// write(2) of the whole buffer through the raw system call, retrying on EINTR and short writes.
bool raw_write_all(int fd, const void* data, std::size_t size);

}  // namespace l6470emu
