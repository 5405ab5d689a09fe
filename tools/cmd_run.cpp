// `l6470emu run`: the board checked, the scenario checked against it (both before the program
// starts: usage errors are status 2), the program run under the preload, its report read back.
#include "tools/cmd_run.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <poll.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <thread>

#include "board/board.hpp"
#include "board/coverage_file.hpp"
#include "board/scenario_runner.hpp"
#include "linux/board_config_file.hpp"
#include "linux/clock.hpp"
#include "linux/device_board.hpp"
#include "tools/run_judgement.hpp"
#include "tools/run_progress.hpp"
#include "tools/run_blocked.hpp"
#include "tools/run_waits.hpp"
#include "tools/run_outcome.hpp"
#include "board/run_report.hpp"
#include "linux/scenario_file.hpp"
#include "linux/serve/daemon.hpp"
#include "linux/virtual_scheduler.hpp"
#include "tools/cmd_report.hpp"
#include "tools/run_recordings.hpp"
#include "tools/kernel_nodes.hpp"
#include "tools/left_processes.hpp"
#include "tools/output_check.hpp"
#include "tools/xml_text.hpp"

extern char** environ;

namespace l6470emu {
namespace {

std::string dir_of(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

bool is_file(const std::string& p) { return access(p.c_str(), R_OK) == 0; }

// $L6470EMU_PRELOAD, else next to this program (a build tree), else where the install put it.
std::string find_preload(std::string& error) {
  if (const char* given = std::getenv("L6470EMU_PRELOAD"); given && *given) {
    if (is_file(given)) return given;
    error = std::string("L6470EMU_PRELOAD=") + given + ": no such file";
    return "";
  }
  char self[4096];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  const std::string exe = n > 0 ? std::string(self, static_cast<std::size_t>(n)) : std::string();
  const std::string here = dir_of(exe);
  for (const std::string& p : {here + "/libl6470emu-preload.so",
                               here + "/../" + std::string(L6470EMU_PRELOAD_RELDIR) + "/libl6470emu-preload.so"})
    if (is_file(p)) return p;
  error = "libl6470emu-preload.so not found next to " + exe + " or in ../" + L6470EMU_PRELOAD_RELDIR +
          " (set L6470EMU_PRELOAD)";
  return "";
}

std::string temp_file(const std::string& what, const std::string& content) {
  const char* dir = std::getenv("TMPDIR");
  std::string path = std::string(dir && *dir ? dir : "/tmp") + "/l6470emu-run-" + what + "-XXXXXX";
  const int fd = mkstemp(path.data());
  if (fd < 0) throw std::runtime_error("cannot create a temporary file in " + dir_of(path));
  std::size_t at = 0;
  while (at < content.size()) {
    const ssize_t w = write(fd, content.data() + at, content.size() - at);
    if (w <= 0) {
      close(fd);
      throw std::runtime_error("cannot write " + path);
    }
    at += static_cast<std::size_t>(w);
  }
  close(fd);
  return path;
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string xml(std::string_view s) { return xml_text(s); }

std::string seconds_number(Tick t) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6f", static_cast<double>(t) / static_cast<double>(kTicksPerSecond));
  return buf;
}

// What an expectation looks at, in words that do not depend on what was seen ("ABS_POS",
// "STATUS", "command GoUntil", "BUSY pulse 2"): its JUnit testcase's name after its step.
std::string expectation_label(const ScenarioExpectation& e) {
  switch (e.kind) {
    case ScenarioExpectation::Kind::reg: return e.name;
    case ScenarioExpectation::Kind::true_position: return "true position";
    case ScenarioExpectation::Kind::status: return "STATUS";
    case ScenarioExpectation::Kind::busy_pulse: return e.pulse ? "BUSY pulse " + std::to_string(e.pulse) : "BUSY pulses";
    case ScenarioExpectation::Kind::command: return "command " + e.name;
    case ScenarioExpectation::Kind::frames: return "frames";
    case ScenarioExpectation::Kind::sanitizer: return "sanitizer";
  }
  return "?";
}

const char* status_words(int status) {
  switch (status) {
    case kRunPassed: return "passed";
    case kRunExpectationFailed: return "an expectation failed";
    case kRunTimedOut: return "the simulated time limit was reached";
    case kRunDeadlocked: return "the program deadlocked in virtual time";
    case kRunSanitizerError: return "the driver sanitizer found a broken rule";
    case kRunProgramFailed: return "the program failed";
    default: return "the program did not run to a report";
  }
}

// The signal (SIGINT, SIGTERM) that asked run to stop while it waited for a preload program.
std::atomic<int> g_stop_signal{0};
extern "C" void on_run_stop_signal(int sig) { g_stop_signal.store(sig); }

// How the program ended, and the report blocks of the processes that used the board.
struct ProgramEnd {
  pid_t pid = 0;
  int wstatus = 0;
  bool wall_timeout = false;  // killed at the simulated time limit, counted on the host's clock (wall time)
  std::chrono::nanoseconds wall_guard_limit{};  // --wall-timeout: how long run waits, whatever the program does
  bool wall_guard = false;    // killed by that guard
  int stopped_by = 0;         // the signal run was stopped by and passed on to the program (0: none)
  RunProgressLine* progress = nullptr;  // the line drawn while it waits (a terminal only)
  const RunWaits* waits = nullptr;      // the processes' published waits (a deadlock across them)
  CrossProcessDeadlock deadlock;        // found there: run ended every process of the program
  std::vector<std::string> blocked;     // what each thread was blocked in when the wall-clock guard ended it
  std::vector<RunReport> blocks;
};

// Our environment, less what would point the program at another board or report.
std::vector<std::string> program_environment(bool keep_ld_preload) {
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e) {
    const std::string_view v(*e);
    bool drop = !keep_ld_preload && v.starts_with("LD_PRELOAD=");
    for (const char* name : {"L6470EMU_CONFIG=", "L6470EMU_SOCKET=", "L6470EMU_TRACE=", "L6470EMU_CHAIN=",
                             "L6470EMU_SCENARIO=", "L6470EMU_RUN_REPORT=", "L6470EMU_TIMEOUT_TICKS=", "L6470EMU_COVERAGE=",
                             "L6470EMU_RUN_PROGRESS="})
      drop = drop || v.starts_with(name);
    if (!drop) env.emplace_back(v);
  }
  return env;
}

// Starts the program; false (and one line said) when it cannot be.
bool spawn_program(const std::vector<std::string>& program, std::vector<std::string> env,
                   const posix_spawnattr_t* attr, pid_t& pid) {
  std::vector<std::string> args = program;
  std::vector<char*> envp, argv;
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // Whatever the program leaves running when it ends, setsid() grandchildren included, comes to
  // this process to be ended (wait_for_program): a process group would not reach those.
  adopt_orphans_from_now();
  const int error = posix_spawnp(&pid, argv[0], nullptr, attr, argv.data(), envp.data());
  if (error == 0) return true;
  std::cerr << "l6470emu run: cannot start " << program[0] << ": " << std::strerror(error) << "\n";
  return false;
}

void wait_for_program_itself(ProgramEnd& run, std::optional<Tick> timeout, const BoardConfig& config);

// Waits for the program. In wall time a limit in simulated seconds is limit / scale seconds of
// real time, after which run kills it. In any time, the wall-clock guard (--wall-timeout) ends a
// program that waits where virtual time cannot see it (a raw system call, sigwait(), a FIFO or
// socket another process holds) or simply runs too long, and says what each thread was blocked in
// (tools/run_blocked.hpp). Processes waiting on each other, each having said so (tools/run_waits.hpp),
// are a deadlock it ends at once. A SIGINT or SIGTERM to run is passed on to the
// program, which gets 5 s to end before SIGKILL; run then writes its reports with the program
// marked as stopped. Once the program has ended, whatever it left running (its children and
// their descendants, setsid() ones too: spawn_program made run their reaper) gets 2 s to end by
// itself, then SIGTERM, then SIGKILL, and run says so in one line: the run is over only when
// nothing of the program holds its output or the board any more. Chosen over watching the
// output pipe, which a program writing to a file does not hold, and over a process group, which
// setsid() leaves.
void wait_for_program(ProgramEnd& run, std::optional<Tick> timeout, const BoardConfig& config) {
  wait_for_program_itself(run, timeout, config);
  if (run.progress) run.progress->finish();
  constexpr std::chrono::seconds kLeftGrace{2};
  const LeftProcesses left = end_left_processes(kLeftGrace);
  if (!left.running.empty()) std::cerr << "l6470emu run: " << left.line(kLeftGrace) << "\n";
}

// wait_for_program up to the end of the program itself.
void wait_for_program_itself(ProgramEnd& run, std::optional<Tick> timeout, const BoardConfig& config) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  std::optional<Clock::time_point> limit_at;
  if (timeout && !config.time.virtual_time)
    limit_at = start + std::chrono::nanoseconds(static_cast<std::int64_t>(static_cast<double>(*timeout) * 250.0 /
                                                                           config.time.scale));
  const auto guard_at = start + run.wall_guard_limit;
  // Readable once the program ended: the wait below returns then, not at its next 5 ms look.
  struct PidFd {
    int fd;
    ~PidFd() {
      if (fd >= 0) close(fd);
    }
  } ended{static_cast<int>(syscall(SYS_pidfd_open, run.pid, 0))};
  const auto kill_now = [&run](bool& why) {
    why = true;
    kill(run.pid, SIGKILL);
    while (waitpid(run.pid, &run.wstatus, 0) < 0 && errno == EINTR) {
    }
  };
  Clock::time_point kill_at{};  // once a signal was passed on: when SIGKILL follows
  bool signalled = false;
  // A deadlock across the processes: seen twice, kWaitsLook apart, the same both times (a wait
  // that another process has just ended has had time to be withdrawn).
  constexpr std::chrono::milliseconds kWaitsLook{100};
  Clock::time_point next_look = start + kWaitsLook;
  CrossProcessDeadlock seen;
  while (true) {
    const pid_t r = waitpid(run.pid, &run.wstatus, WNOHANG);
    if (r == run.pid || (r < 0 && errno != EINTR)) return;
    const auto now = Clock::now();
    if (limit_at && now >= *limit_at) return kill_now(run.wall_timeout);
    if (now >= guard_at && !run.stopped_by) {
      run.blocked = blocked_threads(run.waits ? run.waits->said() : std::map<pid_t, std::vector<std::string>>{});
      return kill_now(run.wall_guard);
    }
    if (const int sig = g_stop_signal.load(); sig && !run.stopped_by) {
      run.stopped_by = sig;
      kill(run.pid, sig);
      kill_at = now + std::chrono::seconds(5);
      signalled = true;
    }
    if (signalled && now >= kill_at) {
      kill(run.pid, SIGKILL);
      signalled = false;
    }
    if (run.progress) run.progress->update();
    if (run.waits && now >= next_look && !run.stopped_by) {
      next_look = now + kWaitsLook;
      CrossProcessDeadlock found = run.waits->look();
      if (found.found() && found == seen) {
        for (const pid_t p : found.processes) kill(p, SIGKILL);
        run.deadlock = std::move(found);
        while (waitpid(run.pid, &run.wstatus, 0) < 0 && errno == EINTR) {
        }
        return;
      }
      seen = std::move(found);
    }
    if (ended.fd >= 0) {
      pollfd p{ended.fd, POLLIN, 0};
      poll(&p, 1, 5);
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
}

// The preload builds the board in every process of the run and appends a report block per
// process to a file; the scenario reaches it as a file too. Returns -1 once the program ran.
int run_under_preload(const BoardConfig& config, const Scenario& scenario, std::optional<Tick> timeout,
                      const std::vector<std::string>& program, ProgramEnd& run) {
  std::string error;
  const std::string preload = find_preload(error);
  if (preload.empty()) {
    std::cerr << "l6470emu run: " << error << "\n";
    return kRunUsage;
  }
  std::string scenario_path, report_path;
  try {
    scenario_path = temp_file("scenario", serialize_scenario(scenario));
    report_path = temp_file("report", "");
  } catch (const std::exception& e) {
    std::cerr << "l6470emu run: " << e.what() << "\n";
    return kRunUsage;
  }
  std::vector<std::string> env = program_environment(false);
  const char* old = std::getenv("LD_PRELOAD");
  env.push_back("LD_PRELOAD=" + preload + (old && *old ? std::string(" ") + old : std::string()));
  env.push_back("L6470EMU_CHAIN=" + describe_board_config(config));
  env.push_back(std::string(kRunScenarioEnv) + "=" + scenario_path);
  env.push_back(std::string(kRunReportEnv) + "=" + report_path);
  if (!config.coverage.empty()) env.push_back(std::string(kCoverageEnv) + "=" + config.coverage);
  if (timeout && config.time.virtual_time) env.push_back(std::string(kRunTimeoutEnv) + "=" + std::to_string(*timeout));
  const std::unique_ptr<RunProgressLine> progress = RunProgressLine::on_terminal();
  if (progress) env.push_back(progress->environment_entry());
  run.progress = progress.get();
  const std::unique_ptr<RunWaits> waits = RunWaits::make(report_path);
  run.waits = waits.get();
  // SIGINT and SIGTERM interrupt the wait (no SA_RESTART) and are passed on to the program.
  struct sigaction stop {}, old_int {}, old_term {};
  stop.sa_handler = on_run_stop_signal;
  sigemptyset(&stop.sa_mask);
  sigaction(SIGINT, &stop, &old_int);
  sigaction(SIGTERM, &stop, &old_term);
  const bool started = spawn_program(program, std::move(env), nullptr, run.pid);
  if (started) {
    wait_for_program(run, timeout, config);
    run.progress = nullptr;
    run.waits = nullptr;
    run.blocks = parse_run_reports(read_all(report_path));
  }
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  unlink(scenario_path.c_str());
  unlink(report_path.c_str());
  return started ? -1 : kRunNotStarted;
}

// The board in this process, served by the daemon's code on a thread of its own through the
// kernel's nodes only (CUSE spidev, UHID CP2112 gpiochips; its socket in a private directory),
// the scenario bound to it; the program started as it is, in wall time, so that what no preload
// reaches (a static or Go program, a setuid one) is judged the same way. Returns -1 once the
// program ran.
int run_on_kernel_nodes(const BoardConfig& config, const Scenario& scenario, bool has_scenario,
                        std::optional<Tick> timeout, const std::vector<std::string>& program, ProgramEnd& run) {
  const char* tmp = std::getenv("TMPDIR");
  std::string dir = std::string(tmp && *tmp ? tmp : "/tmp") + "/l6470emu-run-XXXXXX";
  if (!mkdtemp(dir.data())) {
    std::cerr << "l6470emu run: cannot create a directory in " << dir_of(dir) << ": " << std::strerror(errno) << "\n";
    return kRunUsage;
  }
  // The daemon's thread takes SIGINT, SIGTERM and SIGHUP through its signalfd: every thread of
  // this process blocks them from here on; the program gets the mask and dispositions we had.
  sigset_t stop_signals, old_mask;
  sigemptyset(&stop_signals);
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&stop_signals, sig);
  pthread_sigmask(SIG_BLOCK, &stop_signals, &old_mask);

  struct Shared {
    std::mutex m;
    std::condition_variable cv;
    DeviceBoard* board = nullptr;
    bool daemon_ended = false;
  } shared;
  const FrontEnds nodes = kernel_front_ends(true, true, NodeAccess{});
  const FrontEnds front_ends = [&](DeviceBoard& board, std::ostream&, std::string& error) -> std::shared_ptr<void> {
    std::ostringstream where;
    std::shared_ptr<void> kept = nodes(board, where, error);
    if (!kept) return nullptr;
    if (has_scenario) board.set_scenario(scenario);  // checked against a board like it before
    std::cerr << "l6470emu run: the program reaches the board through the kernel's nodes:\n" << where.str();
    std::lock_guard lock(shared.m);
    shared.board = &board;
    shared.cv.notify_all();
    return kept;
  };
  std::ostringstream daemon_out, daemon_err;  // the daemon thread's until it is joined
  std::thread daemon([&] {
    run_daemon(config, dir + "/serve.sock", daemon_out, daemon_err, front_ends);
    std::lock_guard lock(shared.m);
    shared.daemon_ended = true;
    shared.cv.notify_all();
  });
  DeviceBoard* board = nullptr;
  {
    std::unique_lock lock(shared.m);
    shared.cv.wait(lock, [&] { return shared.board || shared.daemon_ended; });
    board = shared.board;
  }
  const auto end_daemon = [&] {
    if (board) kill(getpid(), SIGTERM);  // to the daemon's signalfd: every thread blocks it
    daemon.join();
    // The daemon saw the signal on its signalfd without taking it: taken here, or it would end
    // this process once unblocked.
    const timespec now{0, 0};
    while (sigtimedwait(&stop_signals, nullptr, &now) > 0) {
    }
    pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
    rmdir(dir.c_str());
    std::string said = daemon_err.str();
    for (std::size_t at = 0; at < said.size();) {
      const std::size_t nl = std::min(said.find('\n', at), said.size());
      std::cerr << "l6470emu run: " << std::string_view(said).substr(at, nl - at) << "\n";
      at = nl + 1;
    }
    const std::string out = daemon_out.str();
    for (std::size_t at = out.find("recorded "); at != std::string::npos; at = out.find("recorded ", at + 1))
      std::cerr << "l6470emu run: " << out.substr(at, out.find('\n', at) - at) << "\n";
  };
  if (!board) {
    end_daemon();
    std::cerr << "l6470emu run: the kernel's nodes could not be made (root, and the modules cuse, uhid and "
                 "hid-cp2112, are needed); the program was not started\n";
    return kRunNotStarted;
  }

  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t defaults;
  sigemptyset(&defaults);
  for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) sigaddset(&defaults, sig);  // the daemon ignores SIGPIPE
  posix_spawnattr_setsigmask(&attr, &old_mask);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  const bool started = spawn_program(program, program_environment(true), &attr, run.pid);
  posix_spawnattr_destroy(&attr);
  if (started) {
    wait_for_program(run, timeout, config);
    {
      std::lock_guard lock(shared.m);
      if (shared.daemon_ended) board = nullptr;  // a SIGINT or SIGTERM to run stopped the board first
    }
    if (!board) {
      end_daemon();
      std::cerr << "l6470emu run: stopped by a signal before the program ended\n";
      return kRunProgramFailed;
    }
    RunReport r;
    r.pid = run.pid;
    r.devices = true;  // whatever it did, it was the only program of the run
    r.scenario = board->finish_scenario(r.outcome);
    r.tick = board->time().now();
    if (const auto report = board->first_unended_check_failure()) {
      r.end = RunEnd::sanitizer;
      r.detail = detail_lines(*report);
    }
    run.blocks.push_back(std::move(r));
  }
  end_daemon();
  return started ? -1 : kRunNotStarted;
}

}  // namespace

RunCommand::RunCommand(CLI::App& app) {
  cmd_ = app.add_subcommand("run", "run a program against an emulated board with a scenario, and judge it");
  cmd_->footer(
      "Exit status: 0 passed, 1 an expectation failed, 2 usage/board/scenario/output error (the program never started), "
      "3 simulated time limit reached (or the wall-clock guard), 4 deadlock in virtual time, 5 driver sanitizer error, 6 the program exited "
      "non-zero or was killed, 7 the program could not be started or left no report. docs/scenarios.md");
  auto* board = cmd_->add_option("--board", board_file_, "board description file (as L6470EMU_CONFIG)");
  auto* chain = cmd_->add_option("--chain", chain_, "board description text (as L6470EMU_CHAIN), e.g. 'chips=L6470 axis.0=...', or a bare chain ('L6470', '3', '2*L6470,L6480')");
  board->excludes(chain);
  cmd_->add_option("--scenario", scenario_file_, "scenario file (YAML, docs/scenarios.md)");
  cmd_->add_option("--time", time_, "the program's clock: virtual (default: the board's time) or wall")
      ->check(CLI::IsMember({"virtual", "wall"}));
  cmd_->add_option("--timeout", timeout_, "simulated time limit (seconds, or 250ms, 2min, ...; default: the scenario's timeout:, else none)");
  cmd_->add_option("--wall-timeout", wall_timeout_,
                   "wall-clock guard: after this long on the host's clock the program is killed and the run ends "
                   "with status 3, whatever its clock (seconds, or 250ms, 2min, ...; default 3600)");
  cmd_->add_option("--junit", junit_, "write a JUnit XML report to this file");
  cmd_->add_option("--record", record_, "record the run into this native trace (one file per chain when several)");
  cmd_->add_option("--html", html_,
                   "write the run's report page to this file (docs/report.md): every chain the program used on one "
                   "page; with --record, from those traces");
  cmd_->add_option("--coverage", coverage_,
                   "collect interface coverage and merge it into this file (every process of the program; docs/coverage.md)");
  cmd_->add_option("--nodes", nodes_,
                   "how the program reaches the board: preload (default: LD_PRELOAD, in this program's process) or "
                   "kernel (the kernel's own /dev/spidevB.C and /dev/gpiochipN through CUSE and UHID, wall time; root, "
                   "modules cuse uhid hid-cp2112: static and Go programs too)")
      ->check(CLI::IsMember({"preload", "kernel"}));
  // For `campaign`: how the run ended, as JSON (linux/run_outcome.hpp); not shown in --help.
  cmd_->add_option("--outcome", outcome_, "write how the run ended as JSON (for campaign)")->group("");
  cmd_->add_flag("--verbose,-v", verbose_, "also print what the world did, step by step, and every expectation that held");
  cmd_->add_option("program", program_, "the program and its arguments (after --)")->required();
}

std::optional<int> RunCommand::run() {
  if (!*cmd_) return std::nullopt;
  auto usage = [](const std::string& line) {
    std::cerr << line << "\n";
    return kRunUsage;
  };
  // 1. The board.
  if (board_file_.empty() && chain_.empty()) return usage("l6470emu run: give the board: --board FILE or --chain DESC");
  // A bare chain ("L6470", "3", "2*L6470,L6480"), as the other subcommands take it, is the chips= of one chain.
  if (!chain_.empty() && chain_.find('=') == std::string::npos) chain_ = "chips=" + chain_;
  ParseResult parsed = board_file_.empty() ? parse_board_config(chain_, "--chain") : load_board_config_file(board_file_);
  if (!parsed.config) return usage(parsed.error.message);
  BoardConfig config = std::move(*parsed.config);
  if (config.chains.empty()) return usage("l6470emu run: the board description has no chain (chips=...)");
  const bool kernel = nodes_ == "kernel";
  if (kernel && cmd_->count("--time") > 0 && time_ == "virtual")
    return usage("l6470emu run: --nodes kernel runs in wall time (the kernel's clocks are not the board's); leave out --time virtual");
  config.time.virtual_time = !kernel && time_ == "virtual";
  config.socket.clear();
  // A test run fails on a broken rule of the chip unless the description says otherwise: the
  // driver sanitizer runs at check=error (status 5) when no check= is given.
  std::string text = chain_;
  if (!board_file_.empty()) {
    std::ifstream in(board_file_);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  if (text.find("check=") == std::string::npos) config.check.level = CheckLevel::error;
  // --html without --record: the run is recorded into a temporary trace for the page (a board
  // of several chains into one beside it per chain, named after it: run_recordings).
  struct TempTrace {
    std::vector<std::string> paths;
    ~TempTrace() {
      for (const std::string& path : paths) unlink(path.c_str());
    }
  } temp_trace;
  if (!html_.empty() && record_.empty()) {
    try {
      record_ = temp_file("trace", "");
    } catch (const std::exception& e) {
      return usage(std::string("l6470emu run: --html: ") + e.what());
    }
    temp_trace.paths.push_back(record_);
    for (const ChainRecording& r : run_recordings(config, record_))
      if (r.path != record_) temp_trace.paths.push_back(r.path);
  }
  if (!record_.empty()) config.trace = record_;
  // The reports, checked before the program starts: one that cannot be written, or that is an
  // input, ends the run here (an output never overwrites an input).
  {
    const std::vector<std::string> inputs{board_file_, scenario_file_, program_.front()};
    for (const auto& [option, path] : {std::pair<const char*, const std::string*>{"--junit", &junit_},
                                       {"--outcome", &outcome_}})
      if (cmd_->count(option) > 0)
        if (const std::string why = output_problem(*path, inputs); !why.empty())
          return usage("l6470emu run: cannot write " + std::string(option) + " " + quoted_text(*path) + ": " + why);
    if (cmd_->count("--record") > 0 && config.chains.size() == 1)
      if (const std::string why = output_problem(record_, inputs); !why.empty())
        return usage("l6470emu run: cannot write --record " + quoted_text(record_) + ": " + why);
    if (!junit_.empty() && junit_ == record_) return usage("l6470emu run: --junit and --record name the same file");
    if (!html_.empty()) {
      if (const std::string why = output_problem(html_, inputs); !why.empty())
        return usage("l6470emu run: cannot write --html " + quoted_text(html_) + ": " + why);
      if (html_ == junit_ || html_ == record_ || html_ == outcome_ || html_ == coverage_)
        return usage("l6470emu run: --html names the same file as another of the run's outputs");
    }
    // L6470EMU_COVERAGE in run's own environment asks the same as --coverage (a suite run with it set).
    const char* env_coverage = std::getenv(kCoverageEnv);
    if (cmd_->count("--coverage") == 0 && env_coverage && *env_coverage) coverage_ = env_coverage;
    if (!coverage_.empty() || cmd_->count("--coverage") > 0) {
      std::string why = check_coverage_output(coverage_);
      if (why.empty() && (coverage_ == junit_ || coverage_ == record_ || coverage_ == outcome_))
        why = "the same file as another of the run's outputs";
      if (why.empty())
        for (const std::string& input : inputs)
          if (!input.empty() && std::filesystem::exists(input) && std::filesystem::exists(coverage_) &&
              std::filesystem::equivalent(input, coverage_))
            why = "the same file as an input";
      if (!why.empty()) return usage("l6470emu run: --coverage: " + why);
      config.coverage = absolute_path(coverage_);
    }
  }

  // 2. The scenario, read and checked against the board.
  Scenario scenario;
  if (!scenario_file_.empty()) {
    ScenarioParse sp = load_scenario_file(scenario_file_);
    if (!sp.scenario) return usage(sp.error);
    scenario = std::move(*sp.scenario);
    try {
      Board probe(config, [](std::string_view) {}, real_host_clock());
      ScenarioRunner check(probe, scenario);
    } catch (const std::invalid_argument& e) {
      return usage(std::string("l6470emu: scenario ") + e.what());
    }
  } else {
    scenario.name = "run";
  }
  std::optional<Tick> timeout = scenario.timeout_ticks;
  if (!timeout_.empty()) {
    timeout = parse_scenario_duration(timeout_);
    if (!timeout || *timeout == 0)
      return usage("l6470emu run: --timeout " + quoted_text(timeout_) + " is not a duration (30, 2.5s, 250ms, 1min)");
  }
  const std::optional<Tick> wall_guard = parse_scenario_duration(wall_timeout_);
  if (!wall_guard || *wall_guard == 0)
    return usage("l6470emu run: --wall-timeout " + quoted_text(wall_timeout_) + " is not a duration (30, 2.5s, 250ms, 1min)");
  // 3. The program: under the preload (the board in its own process), or as it is against the
  // kernel's nodes of a board in this process.
  ProgramEnd run;
  // At most a century: the deadline stays within the steady clock's range.
  run.wall_guard_limit = std::chrono::nanoseconds(std::min<Tick>(*wall_guard, Tick{100} * 365 * 86400 * 4'000'000)) * 250;
  const int started = kernel ? run_on_kernel_nodes(config, scenario, !scenario_file_.empty(), timeout, program_, run)
                             : run_under_preload(config, scenario, timeout, program_, run);
  if (started >= 0) return started;
  // 4. What it came to.
  ProgramExit program_exit;
  program_exit.pid = run.pid;
  program_exit.wstatus = run.wstatus;
  program_exit.wall_timeout = run.wall_timeout;
  program_exit.wall_guard = run.wall_guard;
  program_exit.wall_guard_limit = *wall_guard;
  program_exit.stopped_by = run.stopped_by;
  program_exit.deadlock = std::move(run.deadlock.lines);
  program_exit.blocked = std::move(run.blocked);
  program_exit.blocks = std::move(run.blocks);
  const RunJudgement verdict = judge_run(program_exit, timeout);
  const int status = verdict.status;
  const std::string& ended = verdict.ended;
  const std::string& why = verdict.why;
  const std::vector<ScenarioFailure>& failures = verdict.failures;
  const std::vector<std::string>& passed = verdict.passed;
  const std::vector<std::string>& world = verdict.world;
  const Tick end_tick = verdict.end_tick;
  const std::string words = run.stopped_by ? "run was stopped by a signal" : status_words(status);

  std::ostream& out = std::cerr;
  // Without a report (killed by a signal, _exit()) nothing says when it ended: no "at 0 s".
  out << "l6470emu run: " << program_[0] << " " << ended
      << (run.wall_guard ? std::string()
          : verdict.when_known ? " at " + seconds_text(end_tick) + (config.time.virtual_time ? " of virtual time" : " of board time")
                     : std::string(" (when, in virtual time, is unknown: it left no report)"))
      << "\n";
  for (const auto& d : verdict.detail) out << "  " << d << "\n";
  if (verbose_) {
    for (const auto& w : world) out << "  world: " << w << "\n";
    for (const auto& p : passed) out << "  held: " << p << "\n";
  }
  for (const ScenarioFailure& f : failures)
    out << "  FAILED " << f.where << ": " << f.chip << ": " << f.what << " at " << seconds_text(f.tick) << ": expected "
        << f.expected << ", seen " << f.seen << "\n";
  out << "l6470emu run: " << verdict.expectations << " expectation" << (verdict.expectations == 1 ? "" : "s") << ", "
      << failures.size() << " failed; exit " << status << ": " << words << why << "\n";

  if (!outcome_.empty() && !write_run_outcome(outcome_, verdict.outcome()))
    std::cerr << "l6470emu run: cannot write " << outcome_ << "\n";
  if (!junit_.empty()) {
    // One testcase per expectation, in the scenario's order and named by its step and what it
    // looks at, the same whether it held or not (CI keeps a history per name); a failure
    // element where it failed, a skipped one where it was never judged (the program ended first).
    struct Case {
      std::string name;
      const ScenarioFailure* failure = nullptr;
      bool judged = false;
    };
    std::vector<Case> cases;
    for (const ScenarioStep& st : scenario.steps) {
      if (!st.expect) continue;
      Case c;
      c.name = st.where + ": " + expectation_label(*st.expect);
      for (const ScenarioFailure& f : failures)
        if (!c.failure && f.where == st.where) c.failure = &f;
      for (const std::string& p : passed) c.judged = c.judged || p.rfind(st.where + ": ", 0) == 0;
      cases.push_back(std::move(c));
    }
    for (const ScenarioFailure& f : failures)  // (every failure is a step's; kept whatever comes)
      if (std::none_of(cases.begin(), cases.end(), [&](const Case& c) { return c.failure == &f || (c.failure && c.failure->where == f.where); }))
        cases.push_back(Case{f.where + ": " + f.what, &f, true});
    std::size_t failed = 0, skipped = 0;
    for (const Case& c : cases) {
      failed += c.failure ? 1 : 0;
      skipped += !c.failure && !c.judged ? 1 : 0;
    }
    std::ostringstream x;
    const std::string suite = scenario.name.empty() ? "run" : scenario.name;
    const bool program_failed = run.stopped_by != 0 || status == kRunTimedOut || status == kRunDeadlocked || status == kRunSanitizerError ||
                                status == kRunProgramFailed || status == kRunNotStarted;
    const std::size_t tests = 1 + cases.size();
    const std::string time = seconds_number(end_tick);
    x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    x << "<testsuites name=\"l6470emu run\" tests=\"" << tests << "\" failures=\"" << failed << "\" errors=\""
      << (program_failed ? 1 : 0) << "\" time=\"" << time << "\">\n";
    x << "  <testsuite name=\"" << xml(suite) << "\" tests=\"" << tests << "\" failures=\"" << failed
      << "\" errors=\"" << (program_failed ? 1 : 0) << "\" skipped=\"" << skipped << "\" time=\"" << time << "\">\n";
    const std::string cls = "l6470emu.run." + xml(suite);
    x << "    <testcase classname=\"" << cls << "\" name=\"" << xml("program " + program_[0]) << "\" time=\"" << time << "\">";
    if (program_failed) {
      x << "\n      <error type=\"" << xml(words) << "\" message=\"" << xml(program_[0] + " " + ended + why)
        << "\">";
      for (const auto& d : verdict.detail) x << xml(d) << "\n";
      x << "</error>\n    ";
    }
    x << "</testcase>\n";
    for (const Case& c : cases) {
      x << "    <testcase classname=\"" << cls << "\" name=\"" << xml(c.name) << "\" time=\"0\"";
      if (const ScenarioFailure* f = c.failure) {
        x << ">\n      <failure type=\"expectation\" message=\"" << xml("expected " + f->expected + ", seen " + f->seen) << "\">"
          << xml(f->chip + " at " + seconds_text(f->tick) + ": " + f->what + ": expected " + f->expected + ", seen " + f->seen)
          << "</failure>\n    </testcase>\n";
      } else if (!c.judged) {
        x << ">\n      <skipped message=\"never judged: the program ended before its trigger\"/>\n    </testcase>\n";
      } else {
        x << "/>\n";
      }
    }
    if (verbose_ || !world.empty()) {
      x << "    <system-out>";
      for (const auto& w : world) x << xml(w) << "\n";
      x << "</system-out>\n";
    }
    x << "  </testsuite>\n</testsuites>\n";
    std::ofstream j(junit_, std::ios::trunc);
    j << x.str();
    j.close();
    if (!j) {  // the report CI reads is lost: the run cannot pass
      std::cerr << "l6470emu run: cannot write the JUnit report " << junit_ << "; exit 2\n";
      return kRunUsage;
    }
  }
  if (!html_.empty()) {  // the page of what was recorded: every chain the program opened
    ReportArgs page;
    const bool several = config.chains.size() > 1;
    for (const ChainRecording& r : run_recordings(config, record_)) {
      struct stat st {};
      if (stat(r.path.c_str(), &st) != 0 || st.st_size == 0) continue;  // a chain the program never opened
      page.traces.push_back(r.path);
      if (cmd_->count("--record") == 0)
        page.traces_shown.push_back(several ? "(the run's recording of " + r.chain + ")" : "(the run's recording)");
    }
    if (!coverage_.empty() && std::filesystem::exists(coverage_)) page.coverage = {coverage_};
    page.output = html_;
    page.title = "run: " + program_.front();
    if (page.traces.empty())
      std::cerr << "l6470emu run: no page: the program never used " << (several ? "any chain" : "the chain")
                << " (nothing was recorded)\n";
    else if (run_report(page, std::cerr, "run --html") != 0)
      return kRunUsage;
  }
  return status;
}

}  // namespace l6470emu
