// An SPI trace: CS frames (MOSI and MISO bytes with their virtual time), pin
// events and backdoor faults, in time order. Models what was on the wire and
// the test bench, not what the bytes meant (that is daisychain/decode.hpp).
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/axis_spec.hpp"
#include "core/tick.hpp"
#include "spi/trace_wire.hpp"

namespace l6470emu {

// ---- bounds on the work and memory a trace may ask for --------------------------

/// The most bytes one CS frame may hold (1 MiB, 4096 times the longest chain): every reader
/// refuses a longer frame with one line naming where it is, and the native writer refuses to
/// write one, so that a file (or a gzip bomb) cannot make a reader hold more.
inline constexpr std::size_t kMaxTraceFrameBytes = std::size_t{1} << 20;
/// The longest line a line-based reader takes (8 MiB: a frame of kMaxTraceFrameBytes written
/// as native text, MOSI and MISO, with room to spare).
inline constexpr std::size_t kMaxTraceLineBytes = 8 * kMaxTraceFrameBytes;
/// The most frames a trace may hand out unless the caller allows more (`--max-frames`,
/// `max_frames=`): a few seconds of replay. A `repeat` line asking for more is refused at once.
inline constexpr std::uint64_t kDefaultMaxTraceFrames = 10'000'000;

/// The message for a trace that asks for more than `max_frames` frames: says how to raise the
/// limit ("more than 10000000 frames, the limit (raise it ...)").
std::string too_many_frames(std::uint64_t max_frames);
/// The message for a frame of more than kMaxTraceFrameBytes bytes (`bytes` so far).
std::string frame_too_long(std::uint64_t bytes);
/// The message for a line of more than kMaxTraceLineBytes bytes.
std::string line_too_long();

/// What a trace event is.
enum class TraceEventKind : std::uint8_t {
  frame,  ///< one CS frame: CS falls, bytes are exchanged, CS rises
  pin,    ///< a pin changed level (inputs SW, STCK, STBY) or was observed (outputs BUSY, FLAG)
  fault,  ///< a backdoor event: a fault condition starts or ends, or the ADCIN level changes
  load,   ///< the load on a chip's mechanical axis changes (inertia, friction, force: TraceEvent::load)
  advance,  ///< time was moved on with nothing else happening (`ctl advance`): the chips run up to here
  axis,     ///< an axis is attached to a chip (TraceEvent::text: its AxisSpec text) or removed ("none")
  stops,    ///< the hard stops of a chip's axis change (a scenario's `block:`)
  supply,   ///< the motor supply a chip's axis sees changes (TraceEvent::supply_mV)
};

/// The chip pins a trace can carry, by datasheet name.
enum class TracePin : std::uint8_t {
  SW,    ///< input; low = switch closed
  STCK,  ///< input; rising edge = one microstep in step-clock mode
  STBY,  ///< STBY\RST input; low = logic held in reset
  BUSY,  ///< BUSY\SYNC output (observed); low = busy
  FLAG,  ///< FLAG output (observed); low = alarm
  /// SW as the chip's mechanical axis drove it (observed, like BUSY and FLAG: replay checks it
  /// and does not drive it); written `pin K SW LEVEL axis`.
  SW_AXIS,
  DIR,   ///< input (the L6474's); the direction STCK steps in, high = forward
};

/// Whether a pin event is an observation of the chip (BUSY, FLAG, SW_AXIS), which replay
/// checks, rather than an input the host or the test bench drove.
constexpr bool is_observed_pin(TracePin pin) {
  return pin == TracePin::BUSY || pin == TracePin::FLAG || pin == TracePin::SW_AXIS;
}

/// Backdoor (physical world) events a trace can carry.
enum class TraceFault : std::uint8_t {
  UVLO,      ///< motor supply undervoltage; value 1 = on, 0 = off
  UVLO_ADC,  ///< ADC input undervoltage (gate-driver parts); 1 = on, 0 = off
  OCD,       ///< overcurrent; 1 = on, 0 = off
  STALL_A,   ///< stall / step loss on bridge A; 1 = on, 0 = off
  STALL_B,   ///< stall / step loss on bridge B; 1 = on, 0 = off
  THERMAL,   ///< die temperature class: value is a core Thermal (0 normal .. 3 device shutdown)
  ADCIN,     ///< ADCIN level: value is the 5-bit ADC_OUT code
  // One-shot events (nothing to end):
  POWER_CYCLE,  ///< a brown-out: the chip loses power and is back at once (Chip::power_cycle); value 0
  MISO_FLIP,    ///< the wire: the next frame's MISO byte at the chip's position has bit `value` (0..7) inverted
  LOST_FRAME,   ///< the wire: the chip misses the next frame, as if its CS stayed high; value 0
};
/// How many TraceFault values there are.
inline constexpr unsigned kTraceFaultCount = static_cast<unsigned>(TraceFault::LOST_FRAME) + 1;

/// Datasheet names used in the native format and in reports.
std::string_view to_string(TracePin pin);
std::string_view to_string(TraceFault fault);
/// Names of the THERMAL values: "normal", "warning", "bridge_shutdown", "device_shutdown".
std::string_view thermal_name(std::uint8_t value);

/// One event of a trace, as a view: the byte spans stay valid until the reader moves on.
struct TraceEvent {
  TraceEventKind kind = TraceEventKind::frame;
  Tick tick = 0;      ///< frame: CS falling edge; pin/fault: when it happened
  Tick duration = 0;  ///< frame: ticks from CS falling to CS rising edge (the chips decode at the end)
  std::span<const std::uint8_t> mosi;        ///< frame: bytes sent by the host, in order
  std::span<const std::uint8_t> miso;        ///< frame: bytes received, same length as mosi; empty = none known
  std::span<const std::uint8_t> miso_known;  ///< frame: empty = every miso byte known; else 1 per known byte
  /// frame: how the host drove the wire (SPI mode, bit order, word size, speed, CS timing), as the
  /// trace's last `wire` line says; not known in captures and older files (mode 3, byte by byte).
  TraceWire wire;
  std::uint16_t chip = 0;                    ///< pin/fault: chip index in the chain (0 drives MISO)
  TracePin pin = TracePin::SW;               ///< pin events
  TraceFault fault = TraceFault::UVLO;       ///< fault events
  std::uint8_t value = 0;                    ///< pin: level 0/1; fault: see TraceFault
  LoadSpec load;                             ///< load events: the axis's new load
  /// axis events: the AxisSpec as core/axis_text.hpp writes it ("default" for the default
  /// axis), or "none" when the axis is removed. Valid as long as the byte spans.
  std::string_view text;
  bool has_lower_stop = false;               ///< stops events: the axis's new hard stops (1/128 step)
  bool has_upper_stop = false;
  std::int64_t lower_stop = 0;
  std::int64_t upper_stop = 0;
  std::uint32_t supply_mV = 0;               ///< supply events: the new motor supply, mV
  std::uint64_t line = 0;                    ///< line in the source file (0 = none)
  std::uint64_t repetition = 0;              ///< native `repeat` lines: which repetition (1..), else 0
  double source_time = std::numeric_limits<double>::quiet_NaN();  ///< seconds as in the source file

  /// Tick of the CS rising edge of a frame.
  Tick end() const { return tick + duration; }
  /// Whether MISO byte `i` of a frame is known.
  bool miso_byte_known(std::size_t i) const {
    return !miso.empty() && (miso_known.empty() || miso_known[i] != 0);
  }
  /// Whether the source file gave this event a time of its own.
  bool has_source_time() const { return source_time == source_time; }
  /// Whether this is an observation of a chip's output (a pin event of BUSY, FLAG or SW_AXIS).
  bool is_observation() const { return kind == TraceEventKind::pin && is_observed_pin(pin); }
};

/// Facts about a trace as a whole.
struct TraceHeader {
  std::string name;           ///< file name used in messages ("capture.csv")
  std::string format;         ///< "native", "saleae", "umockdev", "ftrace", "sigrok"
  std::string chain;          ///< the chain the trace was taken from ("3*L6470"); empty = not known
  std::uint64_t chain_line = 0;      ///< where `chain` was written (for error messages)
  /// The board description of the chain the trace was recorded on (native version 2 `board`
  /// lines, one clause per line, as board/board_config.hpp parses it): variants, axes, quirks,
  /// numbering, checks. Empty = not known (captures, version 1 files).
  std::string board;
  std::uint64_t board_line = 0;      ///< where the first `board` line was written
  int version = 0;                   ///< native format version read (0: not a native trace)
  std::vector<std::string> notes;    ///< importer remarks: guessed framing, missing channels...
};

/// A malformed input: file name, line number and what is wrong, as one line of text
/// ("capture.csv:17: MISO \"0xZZ\" is not a byte").
class TraceError : public std::runtime_error {
 public:
  TraceError(std::string file, std::uint64_t line, const std::string& message);
  const std::string& file() const { return file_; }
  std::uint64_t line() const { return line_; }
  /// What is wrong, without the file and line.
  const std::string& reason() const { return reason_; }

 private:
  std::string file_;
  std::uint64_t line_;
  std::string reason_;
};

/// How far a reader has come through its input, for a progress bar.
struct ReadProgress {
  std::uint64_t done = 0;   ///< bytes of the file (or events) behind the reader
  std::uint64_t total = 0;  ///< all of them; 0 = not known
  bool bytes = true;        ///< done and total count bytes (else events)
};

/// A source of trace events, read once from the start (a file being parsed, a Trace in memory).
class TraceReader {
 public:
  virtual ~TraceReader() = default;
  /// Facts known before the first event.
  virtual const TraceHeader& header() const = 0;
  /// Reads the next event into `e`; false at the end. Throws TraceError on malformed input.
  virtual bool next(TraceEvent& e) = 0;
  /// How far reading has come (bytes of a file, or events of a trace in memory).
  virtual ReadProgress progress() const { return {}; }
};

/// Where recorded events go (a native trace file, a Trace in memory).
class TraceSink {
 public:
  virtual ~TraceSink() = default;
  /// Called once, before the first event.
  virtual void write_header(const TraceHeader& header) = 0;
  /// Appends one event; events come in time order.
  virtual void write(const TraceEvent& e) = 0;
};

/// A whole trace in memory: events in a compact array, bytes in one pool.
/// Importers produce one; it can be read any number of times and recorded into.
class Trace final : public TraceSink {
 public:
  TraceHeader header;

  void write_header(const TraceHeader& h) override { header = h; }
  void write(const TraceEvent& e) override;

  /// Number of events.
  std::size_t size() const { return events_.size(); }
  bool empty() const { return events_.empty(); }
  /// Event `i`; its spans stay valid until the trace is changed.
  TraceEvent operator[](std::size_t i) const;
  /// Number of frame events.
  std::size_t frame_count() const { return frames_; }

  /// A reader over the events, from the first one.
  std::unique_ptr<TraceReader> reader() const;

 private:
  struct Stored {
    Tick tick;
    Tick duration;
    double source_time;
    std::uint64_t line;
    std::uint64_t repetition;
    std::uint64_t offset;  // mosi at offset, miso at offset + length, mask after that
    std::uint32_t length;
    std::uint16_t chip;
    TraceEventKind kind;
    std::uint8_t what;   // TracePin / TraceFault
    std::uint8_t value;
    std::uint8_t miso;   // 0 = none known, 1 = all known, 2 = with a mask
    std::uint32_t wire;  // frames: 0 = not known, else wires_[wire - 1]
  };
  std::vector<Stored> events_;
  std::vector<TraceWire> wires_;  // the frames' wire settings, each run of alike frames' once
  std::vector<std::uint8_t> bytes_;
  std::size_t frames_ = 0;
};

// ---- time -------------------------------------------------------------------

/// A time as written in a capture file: whole seconds (floor) and picoseconds 0..10^12-1.
/// Exact for every decimal with up to 12 fractional digits; negative times (before a
/// logic analyzer's trigger) allowed.
struct SourceTime {
  std::int64_t seconds = 0;
  std::int64_t picoseconds = 0;
  double to_double() const { return static_cast<double>(seconds) + static_cast<double>(picoseconds) * 1e-12; }
  friend bool operator==(const SourceTime&, const SourceTime&) = default;
  friend auto operator<=>(const SourceTime&, const SourceTime&) = default;
};

/// How parsing a capture time went.
enum class TimeParse : std::uint8_t {
  ok,
  malformed,     ///< not a decimal number
  out_of_range,  ///< a number, but beyond ±9·10^18 s (or with an exponent beyond ±100000)
};

/// Parses a decimal number ("1.25", "-0.5", ".5", "1.2e-05", "12345.678901") in units of
/// 10^unit_exp10 seconds (0 = s, -6 = µs), rounding beyond 1 ps to nearest.
TimeParse parse_source_time_checked(std::string_view text, int unit_exp10, SourceTime& out);
/// parse_source_time_checked() == TimeParse::ok.
bool parse_source_time(std::string_view text, int unit_exp10, SourceTime& out);

/// Ticks from `origin` to `t`, rounded to nearest; false when t < origin or the span is too long.
bool ticks_between(const SourceTime& origin, const SourceTime& t, Tick& out);

/// Ticks as seconds with 8 decimals, exact ("1.23456725").
std::string format_seconds(Tick t);
/// Ticks as microseconds with 2 decimals, exact ("1.75").
std::string format_microseconds(Tick t);
/// format_seconds / format_microseconds appended to `out` (no allocation when it has room).
void append_seconds(std::string& out, Tick t);
void append_microseconds(std::string& out, Tick t);
/// The most characters format_seconds or format_microseconds gives.
inline constexpr std::size_t kMaxTimeChars = 24;
/// format_seconds / format_microseconds written at `out` (room for kMaxTimeChars); returns the
/// end of what was written.
char* write_seconds(char* out, Tick t);
char* write_microseconds(char* out, Tick t);

// ---- bytes -------------------------------------------------------------------

/// Value of a hex digit, or -1.
constexpr int hex_digit_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/// Bytes as upper-case hex separated by spaces ("D0 00 7E"); unknown MISO bytes as "??".
std::string hex_bytes(std::span<const std::uint8_t> bytes, std::span<const std::uint8_t> known = {});
/// hex_bytes appended to `out`.
void append_hex_bytes(std::string& out, std::span<const std::uint8_t> bytes, std::span<const std::uint8_t> known = {});
/// hex_bytes written at `out` (room for 3 * bytes.size() characters); returns the end of it.
char* write_hex_bytes(char* out, std::span<const std::uint8_t> bytes, std::span<const std::uint8_t> known = {});

}  // namespace l6470emu
