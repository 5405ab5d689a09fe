// The state behind l6470emu.Board: an OS-free Board (board/board.hpp) of a board description in
// virtual time inside the test process, with the spidev device rules (linux/spidev_rules.hpp) per
// chain, the edges of requested pins queued per pin and the board's diagnostics kept as lines,
// and its interface coverage's file (merged into on close, destruction or exit). No Python types
// here (board_bindings.cpp wraps it); no threads or clocks of the host.
#pragma once

#include <linux/spi/spidev.h>

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "board/board.hpp"
#include "coverage_output.hpp"
#include "linux/spidev_rules.hpp"

namespace l6470emu::python {

/// A board of chains as a test process sees it: its own spidev settings per chain, pins that
/// can be watched and waited on, time that moves only when a call moves it. Not thread-safe:
/// the GIL serialises callers.
class PyBoard {
 public:
  /// Edges kept at most per watched pin (older ones are dropped and counted, as a kernel's
  /// event buffer overflows).
  static constexpr std::size_t kMaxEdgesPerPin = 4096;
  /// Diagnostic lines kept at most.
  static constexpr std::size_t kMaxLogLines = 10000;

  /// Builds the board of `config` (which must be in virtual time), collecting interface
  /// coverage when `coverage` asks (its file checked by the caller).
  explicit PyBoard(const BoardConfig& config, const CoverageRequest& coverage = {});
  ~PyBoard();
  PyBoard(const PyBoard&) = delete;
  PyBoard& operator=(const PyBoard&) = delete;

  Board& board() { return *board_; }
  const BoardConfig& config() const { return config_; }

  // ---- spidev: the device's settings, shared by every open file as in the kernel ----

  SpidevSettings& spi(std::size_t chain) { return spi_.at(chain); }
  /// An open of the chain's spidev node (counted; the last close resets the speed, as spidev_release).
  void open(std::size_t chain) { ++users_.at(chain); }
  void close(std::size_t chain);
  /// One SPI_IOC_MESSAGE: `tx` holds the tx data of the transfers with a tx_buf, concatenated;
  /// `rx` gets the rx data. Returns the total length or -errno; on success the board's time is
  /// at the message's end (the caller waited for it, as a kernel transfer takes its bus time).
  long message(std::size_t chain, std::span<const spi_ioc_transfer> xfers, std::span<const std::uint8_t> tx,
               std::span<std::uint8_t> rx);

  // ---- pins -------------------------------------------------------------------------

  /// Starts (true) or stops watching a pin for a requester (counted); the queue of its edges
  /// starts empty with the first watch.
  void watch(std::size_t chain, std::size_t chip, Pin pin, bool on);
  /// Takes the queued edges of a watched pin (tick, level after the edge); `dropped` is added
  /// the number lost to a full queue since the last take.
  std::vector<std::pair<Tick, bool>> take_edges(std::size_t chain, std::size_t chip, Pin pin, std::uint64_t& dropped);
  /// Whether a watched pin has queued edges.
  bool has_edges(std::size_t chain, std::size_t chip, Pin pin) const;
  /// Lets virtual time run until the pin has a queued edge or the board's time reaches
  /// `deadline` (whichever first: the time stops at the edge). Returns whether an edge is queued.
  bool wait_edge(std::size_t chain, std::size_t chip, Pin pin, Tick deadline);

  /// Takes the diagnostics kept so far (one line each); `dropped` gets how many were not kept.
  std::vector<std::string> take_log(std::uint64_t& dropped);
  /// The sanitizer's check=warn lines since the last call (also in the log).
  std::vector<std::string> take_check_lines() { return std::exchange(check_lines_, {}); }

  // ---- interface coverage -------------------------------------------------------------

  /// The coverage file merged into ("" for none or in memory only).
  const std::string& coverage_path() const;
  /// Merges what is new into the coverage file: "" or one line why not.
  std::string flush_coverage() { return coverage_out_ ? coverage_out_->flush() : std::string(); }

 private:
  using PinKey = std::tuple<std::size_t, std::size_t, unsigned>;
  struct EdgeQueue {
    unsigned watchers = 0;
    std::deque<std::pair<Tick, bool>> edges;
    std::uint64_t dropped = 0;
  };

  void on_edge(const PinEdge& edge);

  BoardConfig config_;
  std::unique_ptr<HostClock> clock_;
  std::deque<std::string> log_;
  std::uint64_t log_dropped_ = 0;
  std::vector<std::string> check_lines_;
  std::map<PinKey, EdgeQueue> edges_;
  std::vector<SpidevSettings> spi_;
  std::vector<unsigned> users_;
  std::unique_ptr<Board> board_;         // destroyed before the clock and sinks it refers to
  std::unique_ptr<CoverageOutput> coverage_out_;  // last: destroyed first, merging the board's coverage
};

}  // namespace l6470emu::python
