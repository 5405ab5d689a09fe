// Runs real programs (python3, gpiod tools, the C clients, l6470emu serve) for the linux
// layer's tests: with extra environment, output captured, a time limit, or in the background.
#pragma once

#include <sys/types.h>

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace l6470emu::test {

using Env = std::vector<std::pair<std::string, std::string>>;

/// What a program did: its exit status (128 + signal when killed) and its output.
struct RunResult {
  int status = -1;
  std::string out;
  std::string err;
};

/// Runs `argv` with the test's environment (minus LD_PRELOAD and L6470EMU_*) plus `env`,
/// waiting at most `timeout_s` (then it is killed and status is 128 + SIGKILL).
RunResult run_program(const std::vector<std::string>& argv, const Env& env = {}, double timeout_s = 30);

/// A program running in the background; killed (SIGKILL) when destroyed if still running.
class Background {
 public:
  Background(const std::vector<std::string>& argv, const Env& env = {});
  ~Background();
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;
  pid_t pid() const { return pid_; }
  /// Sends `sig`; waits for the end (at most `timeout_s`); returns the result.
  RunResult stop(int sig, double timeout_s = 10);
  /// Waits for the program to end by itself (at most `timeout_s`, then SIGKILL).
  RunResult wait(double timeout_s = 30);
  /// Output so far.
  std::string out() const;

 private:
  pid_t pid_ = -1;
  std::string out_path_, err_path_;
  bool done_ = false;
  RunResult result_;
};

/// `l6470emu serve --chain CHAIN --socket <fresh path> EXTRA...` in the background, waited for
/// until it listens (ready() says whether it did); stopped with SIGKILL when destroyed if still running.
class ServeDaemon {
 public:
  explicit ServeDaemon(const std::string& chain, const std::vector<std::string>& extra = {});
  bool ready() const { return ready_; }
  const std::string& socket() const { return socket_; }
  /// The environment that sends a program's spidev and gpiochip files to this daemon.
  Env env() const;
  /// `l6470emu ctl --socket SOCKET WORDS...`.
  RunResult ctl(const std::vector<std::string>& words) const;
  Background& process() { return *process_; }

 private:
  std::string socket_;
  std::unique_ptr<Background> process_;
  bool ready_ = false;
};

/// The key=value words of a program's output (the test scripts and clients print their results so).
std::map<std::string, std::string> key_values(const std::string& out);

/// Paths of what the tests run.
std::string build_dir();
std::string preload_library();
std::string l6470emu_program();
std::string client(const std::string& name);  ///< a C client of tests/linux/clients
std::string script(const std::string& name);  ///< a Python script of tests/linux/scripts
/// Debian's python3 (not a pyenv one): the one python3-spidev and python3-libgpiod belong to.
std::string system_python();
/// Why the preload tests cannot run here ("" when they can).
std::string missing_prerequisites();

/// A fresh socket path for a daemon in the test's temporary directory.
std::string temp_socket_path(const std::string& tag);

}  // namespace l6470emu::test
