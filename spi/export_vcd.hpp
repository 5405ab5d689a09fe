// VCD (Value Change Dump) export: a generic writer of wires and integers, the SPI
// wires CS/SCK/MOSI/MISO drawn bit by bit in mode 3, and the export of a trace with
// the pin levels it carries. Emulated BUSY/FLAG and positions come from daisychain/.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "spi/trace.hpp"

namespace l6470emu {

/// Writes a VCD file: declare every signal first, then changes in time order. Once its stream
/// has gone bad (a write error) the next write throws std::ios_base::failure.
class VcdWriter {
 public:
  /// `timescale_ns` is the VCD time unit: 1, 10 or 100 ns (10 ns = sigrok reads it at 100 MHz).
  explicit VcdWriter(std::ostream& out, unsigned timescale_ns = 10);
  VcdWriter(const VcdWriter&) = delete;
  VcdWriter& operator=(const VcdWriter&) = delete;

  /// Declares a 1-bit wire `name` in `scope`; returns its handle. Only before the first change.
  int wire(std::string_view scope, std::string_view name, bool initial);
  /// Declares a number, e.g. a position; returns its handle. It is written as a VCD real:
  /// GTKWave shows it as a value or an analog trace, and sigrok-cli 0.7 skips it cleanly
  /// (its VCD input stops at multi-bit vectors).
  int number(std::string_view scope, std::string_view name, std::int64_t initial);

  /// Sets `signal` to `value` at `time_ns`; times never go back. Unchanged values are skipped.
  void change(std::uint64_t time_ns, int signal, std::int64_t value);
  /// Sets a wire to 'x' (unknown) at `time_ns`.
  void unknown(std::uint64_t time_ns, int signal);
  /// Ends the dump at `time_ns`.
  void finish(std::uint64_t time_ns);

  unsigned timescale_ns() const { return timescale_; }
  /// The last time written, in ns.
  std::uint64_t last_time_ns() const { return last_units_ * timescale_; }

 private:
  struct Signal {
    std::string scope, name, id;
    unsigned bits;
    std::int64_t value;
    bool is_unknown = false;
  };
  void begin();
  void at(std::uint64_t time_ns);
  void put_value(const Signal& s);
  /// Writes out the changes buffered at the current time (bounded: many signals changing at
  /// one time, or times clamped to the last one, never pile up in memory).
  void spill();
  /// Throws std::ios_base::failure once the stream has gone bad (a full disk, a closed pipe):
  /// an export stops at its first write error instead of drawing the rest into nothing.
  void check_output() const;
  static constexpr std::size_t kMaxBufferedBytes = std::size_t{1} << 16;

  std::ostream& out_;
  unsigned timescale_;
  std::vector<Signal> signals_;
  bool begun_ = false;
  std::uint64_t last_units_ = 0;
  bool time_written_ = false;
  std::string buf_;
};

/// The four SPI wires of one chip-select, drawn in SPI mode 3 (CPOL = 1, CPHA = 1:
/// SCK idles high, data changes on the falling edge and is sampled on the rising one).
class SpiVcdWaveform {
 public:
  /// Declares CS, SCK, MOSI and MISO in `scope` of `w`.
  explicit SpiVcdWaveform(VcdWriter& w, std::string_view scope = "spi");

  /// Draws one frame: CS falls at its tick, 8 clocks per byte spread evenly up to its CS rise
  /// (at 5 MHz when the frame has no duration), never past `limit_ns` if it can be helped.
  /// Unknown MISO bytes are drawn as 'x'. Returns the time CS rose, in ns.
  std::uint64_t draw(const TraceEvent& frame, std::uint64_t limit_ns);

 private:
  VcdWriter& w_;
  int cs_, sck_, mosi_, miso_;
};

/// A new pass over a trace's events, from the first (a file read again from its start, a
/// Trace in memory): the exports read a trace more than once instead of holding it whole.
using TracePasses = std::function<std::unique_ptr<TraceReader>()>;

/// The CS falling edge of the frame after each frame, from a pass of its own that runs one
/// frame ahead of the export's: what SpiVcdWaveform::draw takes as its limit, with no more
/// of the trace in memory than that pass's current event.
class NextFrameTicks {
 public:
  /// Reads `pass` up to its first frame.
  explicit NextFrameTicks(std::unique_ptr<TraceReader> pass);
  /// Called once per frame, in order: the tick of the frame after it; nothing after the last.
  std::optional<Tick> after_frame();

 private:
  std::unique_ptr<TraceReader> pass_;
  bool done_ = false;
};

/// VCD export options.
struct VcdOptions {
  unsigned timescale_ns = 10;
};

/// Exports a trace: the SPI wires, and for every chip that has pin events in the trace
/// a wire per pin (SW, STCK, STBY, BUSY, FLAG). Times are the trace's ticks. Streams: it
/// reads three passes side by side (the pins, the events, the next frame's time) and writes as
/// it reads, so its memory does not grow with the trace.
void export_vcd(const TracePasses& passes, std::ostream& out, const VcdOptions& options = {});
/// The same for a trace in memory.
void export_vcd(const Trace& trace, std::ostream& out, const VcdOptions& options = {});

/// Nanoseconds of a tick count.
constexpr std::uint64_t ns_from_ticks(Tick t) { return t * 250; }

}  // namespace l6470emu
