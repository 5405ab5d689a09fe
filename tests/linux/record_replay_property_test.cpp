// The record-then-replay property over every example and a few named runs: each case runs as it
// would for a user, recording into files, and every recording must replay with 0 divergences.
// One place that lists the cases, with the stimuli each must have recorded (so that a clean replay
// is not a replay of nothing); the format's details are recording_test.cpp's.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "run_program.hpp"

namespace l6470emu::test {
namespace {

namespace fs = std::filesystem;

/// What a case's run did: the program's (or the last step's) result, and whether that means it
/// succeeded, with the recordings it left.
struct Recorded {
  RunResult run;
  bool succeeded = false;
  std::string what;                  ///< the run's own failure, in words ("" when it succeeded)
  std::vector<std::string> traces;   ///< every recording the run left
};

/// One case: its name (a test name suffix), how many recordings it must leave, and how to run it
/// recording into `dir` (an empty directory of its own).
struct RecordReplayCase {
  std::string name;
  std::size_t recordings;
  std::function<Recorded(const fs::path& dir)> record;
  bool python = false;  ///< needs the l6470emu Python module of the build
  /// Lines (parts of) the recordings must hold between them: the run's stimuli were recorded,
  /// so a clean replay is not a replay of nothing.
  std::vector<std::string> recorded = {};
};

void PrintTo(const RecordReplayCase& c, std::ostream* os) { *os << c.name; }

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Every file under `dir` whose name ends in ".trace", sorted.
std::vector<std::string> traces_under(const fs::path& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file() && it->path().extension() == ".trace") out.push_back(it->path().string());
  std::sort(out.begin(), out.end());
  return out;
}

/// The first `n` lines of `text`.
std::string head(const std::string& text, int n = 30) {
  std::size_t at = 0;
  for (int i = 0; i < n && at != std::string::npos; ++i) at = text.find('\n', at == 0 ? 0 : at + 1);
  return at == std::string::npos ? text : text.substr(0, at + 1) + "...\n";
}

std::string source(const std::string& path) { return std::string(L6470EMU_SOURCE_DIR) + "/" + path; }
std::string example_program(const std::string& name) { return build_dir() + "/examples/" + name; }

Env python_env() {
  return {{"PYTHONPATH", build_dir() + "/python"}, {"PYTHONDONTWRITEBYTECODE", "1"}, {"MPLBACKEND", "Agg"},
          {"PYTEST_DISABLE_PLUGIN_AUTOLOAD", "1"}};
}

Recorded finish(RunResult r, bool succeeded, const std::string& what, const fs::path& dir) {
  Recorded out;
  out.run = std::move(r);
  out.succeeded = succeeded;
  if (!succeeded) out.what = what + " (exit " + std::to_string(out.run.status) + ")";
  out.traces = traces_under(dir);
  return out;
}

// ---- the examples --------------------------------------------------------------------------

/// A Python example of examples/, each Chain(record=True) it makes recorded into a file
/// (tests/linux/scripts/record_python_example.py: `memory` saves Chain.trace, `file` records
/// with record=PATH).
RecordReplayCase python_example(const std::string& name, const std::string& script_path, const std::string& mode,
                                std::size_t chains) {
  return {name, chains, [=](const fs::path& dir) {
            RunResult r = run_program({system_python(), script("record_python_example.py"), mode, dir.string(),
                                       source(script_path)},
                                      python_env(), 120);
            return finish(r, r.status == 0, "the example failed", dir);
          }, true};
}

Recorded pytest_driver(const fs::path& dir) {
  // The fixtures record by themselves (spidev_board: L6470EMU_TRACE of the driver's process;
  // l6470_board: the in-process Board's trace_path), into each test's tmp_path under --basetemp.
  RunResult r = run_program({system_python(), "-m", "pytest", "-q", "-p", "no:cacheprovider", "--basetemp",
                             (dir / "pytest").string(), source("examples/pytest-driver")},
                            python_env(), 120);
  return finish(r, r.status == 0 && r.out.find("2 passed") != std::string::npos, "pytest did not pass both tests", dir);
}

Recorded vendor_chain(const fs::path& dir) {
  RunResult r = run_program({example_program("vendor_chain")},
                            {{"LD_PRELOAD", preload_library()},
                             {"L6470EMU_CHAIN", "bus=0 cs=0 chips=2xL6470; time=virtual"},
                             {"L6470EMU_TRACE", (dir / "vendor.trace").string()}});
  return finish(r, r.status == 0, "vendor_chain failed", dir);
}

Recorded arduino_sketch(const fs::path& dir) {
  RunResult r = run_program({example_program("arduino_sketch")}, {{"L6470EMU_TRACE", (dir / "sketch.trace").string()}});
  return finish(r, r.status == 0 && r.out.rfind("at 12800 after ", 0) == 0, "the sketch did not end at 12800", dir);
}

Recorded firmware_shim(const fs::path& dir) {
  RunResult r = run_program({example_program("firmware_shim")}, {{"L6470EMU_TRACE", (dir / "shim.trace").string()}});
  return finish(r, r.status == 0, "firmware_shim failed", dir);
}

/// `l6470emu run ... --record DIR/run.trace -- PROGRAM...`, as examples/CMakeLists.txt runs it.
RunResult run_recorded(const fs::path& dir, std::vector<std::string> options, const std::vector<std::string>& program) {
  std::vector<std::string> argv{l6470emu_program(), "run"};
  argv.insert(argv.end(), options.begin(), options.end());
  argv.insert(argv.end(), {"--record", (dir / "run.trace").string(), "--"});
  argv.insert(argv.end(), program.begin(), program.end());
  return run_program(argv, {{"L6470EMU_PRELOAD", preload_library()}}, 90);
}

Recorded run_homing(const fs::path& dir) {
  RunResult r = run_recorded(dir, {"--board", source("examples/run/homing.board"), "--scenario", source("examples/run/homing.yaml")},
                             {example_program("run_homing")});
  return finish(r, r.status == 0, "l6470emu run (homing.c, homing.yaml) did not pass", dir);
}

Recorded run_overcurrent(const fs::path& dir) {
  RunResult r = run_recorded(dir, {"--chain", "chips=L6470", "--scenario", source("examples/run/overcurrent.yaml")},
                             {example_program("run_overcurrent")});
  return finish(r, r.status == 0, "l6470emu run (overcurrent.c, overcurrent.yaml) did not pass", dir);
}

Recorded run_spi_tools(const fs::path& dir) {
  RunResult r = run_recorded(dir, {"--chain", "chips=L6470 mode=3", "--scenario", source("examples/run/spi_tools.yaml")},
                             {"/bin/sh", source("examples/run/spi_tools.sh")});
  return finish(r, r.status == 0, "l6470emu run (spi_tools.sh, spi_tools.yaml) did not pass", dir);
}

// ---- scenarios that change the mechanics -----------------------------------------------------

/// A Python driver for `run`: GetStatus, STALL_TH set to `stall_th` (SetParam; 0: left at its
/// power-up 0x40), Move(FWD, 51200 microsteps), STATUS polled every 50 ms until BUSY is released,
/// 300 ms more, then STATUS and ABS_POS printed. Few frames (world.yaml allows at most 256).
std::string move_driver(const fs::path& dir, int stall_th) {
  const fs::path path = dir / "move_driver.py";
  std::ofstream(path) << "import spidev, time\n"
                         "s = spidev.SpiDev(); s.open(0, 0); s.mode = 3; s.max_speed_hz = 1000000\n"
                         "x = lambda *bs: [s.xfer2([b])[0] for b in bs]\n"
                         "status = lambda: (lambda r: r[1] << 8 | r[2])(x(0xD0, 0, 0))\n"
                         "seen = [status()]\n"
                      << (stall_th ? "x(0x14, " + std::to_string(stall_th) + ")\n" : std::string()) <<
                         "x(0x41, 0x00, 0xC8, 0x00)\n"
                         "for _ in range(100):\n"
                         "    time.sleep(0.05)\n"
                         "    seen.append(status())\n"
                         "    if seen[-1] & 2: break\n"
                         "time.sleep(0.3)\n"
                         "seen.append(status())\n"
                         "p = x(0x21, 0, 0, 0)\n"
                         "print('status=' + ','.join(f'{v:#06x}' for v in seen), f'abs_pos={p[1] << 16 | p[2] << 8 | p[3]}')\n";
  return path.string();
}

Recorded scenario_stall(const fs::path& dir) {
  // tests/fuzz/corpus/scenario/world.yaml: a hard stop (block:) put in the carriage's way at
  // 25600 once ABS_POS reaches 12800, and a load; the rotor stalls against the stop, which the
  // chip sees with STALL_TH 0x30 (1.53 A, as examples/homing/homing.py): STEP_LOSS_A/B (bits 13,
  // 14, active low) in the STATUS the driver polls.
  RunResult r = run_recorded(dir, {"--chain", "chips=L6470 axis.0=stops=-1000000..1000000", "--scenario",
                                   source("tests/fuzz/corpus/scenario/world.yaml")},
                             {system_python(), move_driver(dir, 0x30)});
  const bool stalled = r.out.find(",0x1e") != std::string::npos || r.out.find(",0x3e") != std::string::npos ||
                       r.out.find(",0x5e") != std::string::npos;
  return finish(r, r.status == 0 && stalled, "l6470emu run (world.yaml: block, load) did not pass with a stall seen", dir);
}

Recorded scenario_supply(const fs::path& dir) {
  // The motor supply drops below the UVLO threshold during the move (UVLO, bridges off) and
  // comes back while the driver still polls.
  const fs::path scenario = dir / "supply.yaml";
  std::ofstream(scenario) << "name: supply dip\n"
                             "steps:\n"
                             "  - on: {command: Move}\n"
                             "    delay: 200ms\n"
                             "    do: {supply_mV: 7000}\n"
                             "  - on: {command: Move}\n"
                             "    delay: 300ms\n"
                             "    do: {supply_mV: 12000}\n"
                             "  - at: end\n"
                             "    expect: {command: Move, count: 1}\n";
  RunResult r = run_recorded(dir, {"--chain", "chips=L6470 axis.0=stops=-1000000..1000000", "--scenario", scenario.string()},
                             {system_python(), move_driver(dir, 0)});
  // UVLO (bit 9, active low) seen in a STATUS: 0x7C.. or 0x1C.. instead of 0x7E..
  const bool dipped = r.out.find(",0x7c") != std::string::npos || r.out.find(",0x1c") != std::string::npos;
  return finish(r, r.status == 0 && dipped, "l6470emu run (supply_mV dip) did not pass with UVLO seen", dir);
}

// ---- the daemon ------------------------------------------------------------------------------

/// Ends `daemon` with SIGTERM (which closes its recordings) and says whether it ended cleanly.
bool stop_daemon(std::unique_ptr<ServeDaemon>& daemon, RunResult& out) {
  out = daemon->process().stop(SIGTERM);
  daemon.reset();
  return out.status == 0;
}

/// A Python program on /dev/spidevBUS.CS of a one-chip chain: `body` runs with x(*bytes) sending
/// one frame per byte and returning the answers.
std::vector<std::string> spidev_python(int bus, int cs, const std::string& body) {
  return {system_python(), "-c",
          "import spidev, time\ns = spidev.SpiDev(); s.open(" + std::to_string(bus) + ", " + std::to_string(cs) +
              "); s.mode = 3\nx = lambda *bs: [s.xfer2([b])[0] for b in bs]\n" + body};
}

Recorded daemon_ctl_faults(const fs::path& dir) {
  auto daemon = std::make_unique<ServeDaemon>("bus=0 cs=0 chips=L6470",
                                              std::vector<std::string>{"--record", (dir / "serve.trace").string()});
  if (!daemon->ready()) return finish(daemon->process().stop(SIGKILL), false, "serve did not start", dir);
  const Env env = daemon->env();
  const std::string status = "print([hex(v) for v in x(0xD0, 0, 0)])\n";
  std::vector<std::vector<std::string>> steps{
      {"fault", "ocd", "on"},        {"fault", "thermal", "warning"}, {"fault", "stall-a", "on"},
      {"fault", "stall-b", "on"},    {"fault", "uvlo", "on"},         {"fault", "uvlo-adc", "on"},
      {"adc", "17"},                 {"sw", "closed"},                {"fault", "miso-flip", "3"},
      {"fault", "lost-frame"},       {"fault", "reset"}};
  RunResult r = run_program({system_python(), script("spidev_sequence.py"), "0", "0"}, env);
  if (r.status != 0) return finish(r, false, "spidev_sequence.py failed", dir);
  // A move in flight while the faults come: the chip answers STATUS between them.
  r = run_program(spidev_python(0, 0, "x(0xD0, 0, 0); x(0x50, 0, 0x40, 0)\n"), env);
  for (const auto& words : steps) {
    RunResult c = daemon->ctl(words);
    if (c.status != 0) return finish(c, false, "ctl " + words[0] + " failed", dir);
    r = run_program(spidev_python(0, 0, status), env);
    if (r.status != 0) return finish(r, false, "the status client failed", dir);
  }
  for (const auto& words : std::vector<std::vector<std::string>>{{"fault", "ocd", "off"},
                                                                 {"fault", "thermal", "device-shutdown"},
                                                                 {"fault", "thermal", "normal"},
                                                                 {"fault", "uvlo", "off"},
                                                                 {"sw", "open"}})
    if (RunResult c = daemon->ctl(words); c.status != 0) return finish(c, false, "ctl " + words[0] + " failed", dir);
  r = run_program(spidev_python(0, 0, status + "x(0xB8)\n" + status), env);
  if (r.status != 0) return finish(r, false, "the last client failed", dir);
  RunResult d;
  const bool stopped = stop_daemon(daemon, d);
  return finish(d, stopped, "serve did not end cleanly on SIGTERM", dir);
}

Recorded daemon_several_clients(const fs::path& dir) {
  // Three chains, four client programs: three at once (one per chain), then a second program on
  // the first chain; and a ctl switch change between them.
  auto daemon = std::make_unique<ServeDaemon>("bus=0 cs=0 chips=L6470; bus=0 cs=1 chips=L6470; bus=1 cs=0 chips=L6470",
                                              std::vector<std::string>{"--record", (dir / "serve.trace").string()});
  if (!daemon->ready()) return finish(daemon->process().stop(SIGKILL), false, "serve did not start", dir);
  const Env env = daemon->env();
  std::vector<std::unique_ptr<Background>> clients;
  for (const auto& [bus, cs] : std::vector<std::pair<std::string, std::string>>{{"0", "0"}, {"0", "1"}, {"1", "0"}})
    clients.push_back(std::make_unique<Background>(
        std::vector<std::string>{system_python(), script("spidev_sequence.py"), bus, cs}, env));
  for (auto& c : clients)
    if (RunResult r = c->wait(60); r.status != 0) return finish(r, false, "a concurrent client failed", dir);
  for (const auto& words : std::vector<std::vector<std::string>>{{"sw", "closed", "--chip", "0"},
                                                                 {"fault", "ocd", "on", "--chain", "spidev1.0"},
                                                                 {"adc", "9", "--chain", "spidev0.1"}})
    if (RunResult c = daemon->ctl(words); c.status != 0) return finish(c, false, "ctl " + words[0] + " failed", dir);
  RunResult r = run_program(spidev_python(0, 0, "print(x(0xD0, 0, 0)); x(0x40, 0, 0x10, 0)\n"
                                                "while not x(0xD0, 0, 0)[2] & 2: time.sleep(0.005)\n"
                                                "print(x(0x21, 0, 0, 0))\n"),
                            env);
  if (r.status != 0) return finish(r, false, "the second client of spidev0.0 failed", dir);
  RunResult d;
  const bool stopped = stop_daemon(daemon, d);
  return finish(d, stopped, "serve did not end cleanly on SIGTERM", dir);
}

Recorded daemon_virtual_time(const fs::path& dir) {
  // A virtual-time daemon with a homing axis: a homing program stepped by `ctl advance`, then a
  // heavier load, a Move against it, an overcurrent, and time advanced between them.
  auto daemon = std::make_unique<ServeDaemon>(
      "bus=0 cs=0 chips=L6470 axis.0=stops=-6400..300000,start=51200,switch=home@0:below:hyst=64",
      std::vector<std::string>{"--virtual-time", "--record", (dir / "serve.trace").string()});
  if (!daemon->ready()) return finish(daemon->process().stop(SIGKILL), false, "serve did not start", dir);
  const Env env = daemon->env();
  RunResult homed;
  {
    Background homing({system_python(), script("spidev_homing.py"), "0", "0"}, env);
    for (int i = 0; i < 2000; ++i) {
      const std::string out = homing.out();
      if (out.find("homed\n") != std::string::npos || out.find("FAIL") != std::string::npos) break;
      daemon->ctl({"advance", "100"});
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    homed = homing.wait(30);
  }
  if (homed.status != 0) return finish(homed, false, "spidev_homing.py did not home", dir);
  for (const auto& words : std::vector<std::vector<std::string>>{{"axis", "load", "friction=0.3", "--chip", "0"},
                                                                 {"advance", "50"}})
    if (RunResult c = daemon->ctl(words); c.status != 0) return finish(c, false, "ctl " + words[0] + " failed", dir);
  RunResult moved = run_program(spidev_python(0, 0, "x(0x41, 0, 0x32, 0)\n"), env);
  if (moved.status != 0) return finish(moved, false, "the Move client failed", dir);
  for (const auto& words : std::vector<std::vector<std::string>>{{"advance", "1500"},
                                                                 {"fault", "ocd", "on"},
                                                                 {"advance", "20"},
                                                                 {"fault", "ocd", "off"},
                                                                 {"axis", "load", "friction=0", "--chip", "0"},
                                                                 {"advance", "10"}})
    if (RunResult c = daemon->ctl(words); c.status != 0) return finish(c, false, "ctl " + words[0] + " failed", dir);
  RunResult last = run_program(spidev_python(0, 0, "print(x(0xD0, 0, 0), x(0x21, 0, 0, 0))\n"), env);
  if (last.status != 0) return finish(last, false, "the last client failed", dir);
  RunResult d;
  const bool stopped = stop_daemon(daemon, d);
  return finish(d, stopped, "serve did not end cleanly on SIGTERM", dir);
}

const std::vector<RecordReplayCase>& cases() {
  static const std::vector<RecordReplayCase> all{
      python_example("RetargetPyRecordedInMemory", "examples/retarget/retarget.py", "memory", 1),
      python_example("RetargetPyRecordedToAFile", "examples/retarget/retarget.py", "file", 1),
      python_example("FiveMotorsPyRecordedInMemory", "examples/five_motors/five_motors.py", "memory", 1),
      python_example("FiveMotorsPyRecordedToAFile", "examples/five_motors/five_motors.py", "file", 1),
      // chain-0: the switch homing, chain-1: the stall (sensorless) homing.
      python_example("HomingPySwitchAndStallChainsRecordedInMemory", "examples/homing/homing.py", "memory", 2),
      python_example("HomingPySwitchAndStallChainsRecordedToFiles", "examples/homing/homing.py", "file", 2),
      {"PytestDriverBothFixtures", 2, pytest_driver, true},
      {"VendorChainUnderThePreload", 1, vendor_chain},
      {"ArduinoSketch", 1, arduino_sketch},
      {"FirmwareShim", 1, firmware_shim},
      {"RunHomingCWithItsBoardAndScenario", 1, run_homing},
      {"RunOvercurrentCWithItsScenario", 1, run_overcurrent},
      {"RunSpiToolsShellScript", 1, run_spi_tools},
      {"ScenarioWithAHardStopTheRotorStallsOn", 1, scenario_stall, false, {" load 0 "}},
      {"ScenarioWithASupplyDip", 1, scenario_supply, false, {" fault 0 UVLO on\n"}},
      {"DaemonWithCtlFaults", 1, daemon_ctl_faults, false,
       {" fault 0 OCD on\n", " fault 0 THERMAL warning\n", " fault 0 STALL_A on\n", " fault 0 UVLO on\n",
        " fault 0 UVLO_ADC on\n", " fault 0 ADCIN 17\n", " pin 0 SW 0\n", " fault 0 OCD off\n"}},
      {"DaemonWithSeveralClientsOnThreeChains", 3, daemon_several_clients, false,
       {" pin 0 SW 0\n", " fault 0 OCD on\n", " fault 0 ADCIN 9\n"}},
      {"DaemonInVirtualTimeWithAnAxisLoadsAndAdvance", 1, daemon_virtual_time, false,
       {" axis.0=stops=-6400..300000,start=51200,switch=home@0", " load 0 ", " advance\n", " fault 0 OCD on\n"}},
  };
  return all;
}

/// Whether `l6470emu plot` can draw here: Debian's python3-matplotlib and this build's Python
/// package (a tree built without it, as the sanitizer tree is, has no plot). Says once why not.
bool can_plot() {
  static const bool yes = [] {
    std::string why;
    if (!std::filesystem::exists(build_dir() + "/python/l6470emu/__init__.py"))
      why = "this build has no Python package (" + build_dir() + "/python)";
    else if (run_program({system_python(), "-c", "import matplotlib"}).status != 0)
      why = "python3-matplotlib is missing";
    if (!why.empty()) std::fprintf(stderr, "record/replay property test: plot not checked: %s\n", why.c_str());
    return why.empty();
  }();
  return yes;
}

class RecordThenReplay : public ::testing::TestWithParam<RecordReplayCase> {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
    dir_ = fs::temp_directory_path() / ("l6470emu-record-replay-" + std::to_string(getpid()) + "-" + GetParam().name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    if (!HasFailure()) fs::remove_all(dir_, ec);
    else std::cerr << "the recordings are kept in " << dir_.string() << "\n";
  }
  fs::path dir_;
};

TEST_P(RecordThenReplay, TheRunSucceedsAndEachOfItsRecordingsReplaysWithNoDivergence) {
  const RecordReplayCase& c = GetParam();
  if (c.name == "RunSpiToolsShellScript" && access("/usr/bin/spi-pipe", X_OK) != 0)
    GTEST_SKIP() << "spi-tools not installed (apt install spi-tools)";
  if (c.python && access((build_dir() + "/python/l6470emu/__init__.py").c_str(), F_OK) != 0)
    GTEST_SKIP() << "the Python module is not built here (a sanitizer build has none)";
  const Recorded rec = c.record(dir_);
  ASSERT_TRUE(rec.succeeded) << rec.what << "\n--- stdout\n" << head(rec.run.out) << "--- stderr\n" << head(rec.run.err, 60);
  ASSERT_EQ(rec.traces.size(), c.recordings) << "the run left these recordings: " << ::testing::PrintToString(rec.traces)
                                             << "\n--- stderr\n" << head(rec.run.err);
  std::string all;
  for (const std::string& trace : rec.traces) all += read_text(trace);
  for (const std::string& line : c.recorded) EXPECT_NE(all.find(line), std::string::npos) << "not recorded: " << line;
  for (const std::string& trace : rec.traces) {
    SCOPED_TRACE(trace);
    const std::string text = read_text(trace);
    EXPECT_EQ(text.rfind("l6470emu-trace ", 0), 0u) << "not a native trace:\n" << head(text, 5);
    EXPECT_NE(text.find(" frame "), std::string::npos) << "no frame recorded:\n" << head(text);
    const RunResult replay = run_program({l6470emu_program(), "replay", trace}, {}, 60);
    EXPECT_TRUE(replay.status == 0 && replay.out.find(": matched") != std::string::npos)
        << "replay exit " << replay.status << "\n" << head(replay.out, 40) << head(replay.err, 20) << "--- the trace\n" << head(text, 12);
    const RunResult decode = run_program({l6470emu_program(), "decode", trace}, {}, 60);
    EXPECT_TRUE(decode.status == 0 && decode.out.find("DIVERGED") == std::string::npos)
        << "decode exit " << decode.status << "\n" << head(decode.err, 20);
    if (can_plot()) {
      const RunResult plot = run_program({l6470emu_program(), "plot", trace, "-o", trace + ".png"}, {}, 120);
      EXPECT_EQ(plot.status, 0) << "plot\n" << head(plot.out, 10) << head(plot.err, 20);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(EveryExampleAndNamedRun, RecordThenReplay, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<RecordReplayCase>& info) { return info.param.name; });

}  // namespace
}  // namespace l6470emu::test
