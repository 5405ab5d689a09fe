// Helpers for the trace tests: fixture files, temporary files, running a program and
// capturing its output, and a small recorded session. Header-only.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "daisychain/recording_chain.hpp"
#include "spi/trace.hpp"

namespace l6470emu::test {

/// A CS frame event at tick `t` lasting `d` ticks.
inline TraceEvent frame_at(Tick t, Tick d, const std::vector<std::uint8_t>& mosi, const std::vector<std::uint8_t>& miso) {
  TraceEvent e;
  e.kind = TraceEventKind::frame;
  e.tick = t;
  e.duration = d;
  e.mosi = mosi;
  e.miso = miso;
  return e;
}

/// Path of a file under fixtures/traces.
inline std::string fixture_path(const std::string& name) {
  return std::string(L6470EMU_SOURCE_DIR) + "/fixtures/traces/" + name;
}

/// Contents of a file.
inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Contents of a fixture.
inline std::string fixture(const std::string& name) { return read_text(fixture_path(name)); }

/// A temporary directory, removed with its files at the end of the test.
class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/l6470emu-test-XXXXXX";
    const char* d = mkdtemp(tmpl);
    if (d == nullptr) throw std::runtime_error("mkdtemp failed");
    dir_ = d;
  }
  ~TempDir() { std::system(("rm -rf '" + dir_ + "'").c_str()); }
  std::string file(const std::string& name) const { return dir_ + "/" + name; }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(file(name), std::ios::binary) << text;
    return file(name);
  }

 private:
  std::string dir_;
};

/// Whether `program` can be found on PATH.
inline bool have_program(const std::string& program) {
  return std::system(("command -v " + program + " >/dev/null 2>&1").c_str()) == 0;
}

/// Result of a program run.
struct RunResult {
  int status = -1;  ///< exit status (-1 when it did not exit normally)
  std::string out;  ///< standard output and standard error, merged
};

/// Runs a shell command line, merging standard error into the output.
inline RunResult run_command(const std::string& command) {
  RunResult r;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf;
  std::size_t got;
  while ((got = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), got);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

/// A small recorded session on a chain of `chips` L6470s: each helper sends one command to
/// every chip, one CS frame per byte position (the usual daisy-chain driver).
struct RecordedSession {
  Chain chain;
  Trace trace;
  RecordingChain rec;
  explicit RecordedSession(std::size_t chips, RecordOptions options = {})
      : chain(chips), rec(chain, trace, options) {}

  /// One frame at now + gap ticks, 7 ticks per byte (about 4.5 MHz); returns MISO.
  std::vector<std::uint8_t> frame(const std::vector<std::uint8_t>& tx, Tick gap = 8) {
    rec.advance_to(rec.now() + gap);
    rec.select();
    std::vector<std::uint8_t> rx(tx.size());
    for (std::size_t i = 0; i < tx.size(); ++i) {
      rec.advance_to(rec.now() + 7);
      rx[i] = rec.exchange(tx[i]);
    }
    rec.deselect();
    return rx;
  }
  /// Sends per_chip[k] to chip k, right-aligned; returns the MISO of every frame.
  std::vector<std::vector<std::uint8_t>> all(const std::vector<std::vector<std::uint8_t>>& per_chip) {
    std::size_t len = 0;
    for (const auto& c : per_chip) len = std::max(len, c.size());
    std::vector<std::vector<std::uint8_t>> out;
    for (std::size_t f = 0; f < len; ++f) {
      std::vector<std::uint8_t> tx(chain.size(), 0x00);
      for (std::size_t k = 0; k < per_chip.size(); ++k) {
        const std::size_t pad = len - per_chip[k].size();
        if (f >= pad) tx[k] = per_chip[k][f - pad];
      }
      out.push_back(frame(tx));
    }
    return out;
  }
  /// The same command to every chip.
  std::vector<std::vector<std::uint8_t>> each(const std::vector<std::uint8_t>& cmd) {
    return all(std::vector<std::vector<std::uint8_t>>(chain.size(), cmd));
  }
  void wait_ms(std::uint64_t ms) {
    rec.advance_to(rec.now() + ticks_from_ms(ms));
    rec.observe_outputs();
  }
};

}  // namespace l6470emu::test
