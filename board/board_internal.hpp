// Board's private state, shared by board.cpp (chains, SPI, pins, time) and board_record.cpp
// (recordings). Not part of the public API.
#pragma once

#include <array>
#include <compare>

#include "board/board.hpp"
#include "board/pulse_train.hpp"
#include "board/trace_recorder.hpp"

namespace l6470emu {

/// One chain of the board, its pins and its recording.
struct Board::ChainState {
  /// One level per pin of a chip, indexed by Pin.
  using PinLevels = std::array<bool, kPinsPerChip>;
  /// A watched pin; sorted by chip, then pin (a gpiochip's line order). Watched by the front
  /// (its edges go to the edge sink), by the observer (to the observer sink), or both.
  struct WatchedPin {
    std::size_t chip = 0;
    Pin pin = Pin::BUSY;
    bool by_front = false;
    bool by_observer = false;
    bool operator<(const WatchedPin& o) const { return chip < o.chip || (chip == o.chip && pin < o.pin); }
    bool same_pin(const WatchedPin& o) const { return chip == o.chip && pin == o.pin; }
  };

  /// How one chip's diagnostics are logged: its name in the log and how many of each kind came.
  ChainConfig config;
  Chain chain;
  std::string name;                   // "spidev0.0"
  std::size_t index = 0;              // in the board description
  bool wired = false;                 // its pins are on lines (gpiochip=): wire levels are kept
  std::vector<PinLevels> wire;        // inputs on lines: the level each is driven to
  std::vector<PinLevels> last;        // watched pins: the level last reported
  std::vector<WatchedPin> watched;    // sorted
  std::unique_ptr<ChainTraceRecorder> recorder;  // the trace being recorded, if any
  std::unique_ptr<ChainChecker> checker;         // the sanitizer's checks of this chain
  std::unique_ptr<ChainBus> bus;                 // what begin_transfer hands out
  PinLevelBus pin_bus;                           // SPI at the pins: the edges of the byte under way
  std::vector<Chip::CommandSink> command_observers;  // per chip: set_command_observer's sink
  bool touched = false;               // a transfer or a stimulus has reached the chips since power-up
  // The next change of a watched BUSY/FLAG as predict_next_edge found it (kNever: none), valid
  // until something other than time reaches the chain (a byte, a CS edge, an input, a fault,
  // a new watch): until then the chain advances to any earlier tick without probing.
  bool prediction_valid = false;
  Tick predicted_edge = kNever;
  /// A pulse train driving an input pin (board_pulses.cpp), with the edges already applied.
  struct Train {
    std::size_t chip = 0;
    Pin pin = Pin::STCK;
    PulseTrain train;
    std::uint64_t rises = 0, falls = 0;
    /// The tick of the next edge not yet applied (kNever when the train has no more).
    Tick next_edge() const;
  };
  std::vector<Train> trains;
  /// Rising edges of trains that have ended, by chip and pin (pulse_train_rises).
  std::vector<std::pair<std::pair<std::size_t, Pin>, std::uint64_t>> train_rises;
  void add_train_rises(const Train& t) {
    for (auto& [where, n] : train_rises)
      if (where == std::pair{t.chip, t.pin}) return void(n += t.rises);
    train_rises.push_back({{t.chip, t.pin}, t.rises});
  }
  ChainState(const ChainConfig& c, std::vector<Chip> chips) : config(c), chain(std::move(chips)) {}
};

// Inline: it runs after every step of a chain's time and every transfer, recorded or not.
inline void Board::record_outputs(ChainState& c) {
  if (!c.recorder) return;
  c.recorder->observe_outputs();  // free when nothing changed since the last look
  if (!c.recorder->error().empty()) [[unlikely]]
    drop_failed_recording(c);
}

}  // namespace l6470emu
