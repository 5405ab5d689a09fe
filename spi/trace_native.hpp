// The native trace format (docs/trace-format.md): line-based text, one CS frame per
// line, version 3 (versions 1 and 2 read too), plain or gzip. Reader (streaming, for traces of any length, expanding
// `repeat` lines as it goes) and writer (flushed event by event, so a killed process leaves
// a complete file; collapsing runs of repeated frames into `repeat` lines). No other formats here.
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "spi/trace.hpp"
#include "spi/trace_output.hpp"

namespace l6470emu {

/// The first line of every native trace.
inline constexpr std::string_view kNativeTraceMagic = "l6470emu-trace";
/// The format version this code writes (it reads versions 1 to 3). Version 2 added the
/// `board` header lines, the `load` and `advance` events and open `repeat` lines; version 3 the
/// `wire` lines (the host's SPI settings, spi/trace_wire.hpp).
inline constexpr int kNativeTraceVersion = 3;
/// The comment the writer puts under the header (after `chain`), so a reader of the file
/// knows which end chip 0 is: the chain's own order, whatever a tool shows.
inline constexpr std::string_view kNativeTraceNumbering =
    "chip numbers count from the MISO end: chip 0 drives MISO, byte k of a frame goes to chip k";

/// The most bytes of `board` lines a reader takes (a board description is a few lines).
inline constexpr std::size_t kMaxBoardBytes = std::size_t{1} << 20;

/// The most frames a `repeat` line can repeat as one group.
inline constexpr std::size_t kMaxRepeatGroup = 16;
/// The most repetitions one `repeat` line can stand for (the writer starts a new line beyond).
inline constexpr std::uint64_t kMaxRepeatCount = 1'000'000'000'000ull;
/// The latest time a native trace holds, in seconds: every event's time, a frame's CS rising
/// edge, a frame's duration and a `repeat` period are at most this. The writer refuses an event
/// beyond it (std::runtime_error) rather than write what its reader would refuse.
inline constexpr std::uint64_t kMaxNativeTraceSeconds = 1'000'000'000'000ull;
/// kMaxNativeTraceSeconds in ticks (4·10^18, well inside a Tick).
inline constexpr Tick kMaxNativeTraceTick = kMaxNativeTraceSeconds * kTicksPerSecond;

class TraceFileReader;

/// Reads a native trace event by event; memory use does not grow with its length (a line is
/// at most kMaxTraceLineBytes, a frame at most kMaxTraceFrameBytes).
///
/// The work a trace asks for is bounded too: it may hand out at most `max_frames` frames (0: no
/// limit). A frame line past the limit, or a `repeat` line whose repetitions would pass it, is a
/// TraceError naming that line, before any of the work is done.
class NativeTraceReader final : public TraceReader {
 public:
  /// Opens `path` (gzip-compressed or not: recognised by its first bytes). Throws TraceError
  /// when it cannot be read or is not a native trace of version 1 to 3.
  explicit NativeTraceReader(const std::string& path, std::uint64_t max_frames = kDefaultMaxTraceFrames);
  /// Reads `text` (kept by reference: it must outlive the reader), called `name` in messages.
  NativeTraceReader(std::string_view text, std::string name, std::uint64_t max_frames = kDefaultMaxTraceFrames);
  ~NativeTraceReader() override;
  NativeTraceReader(const NativeTraceReader&) = delete;
  NativeTraceReader& operator=(const NativeTraceReader&) = delete;

  const TraceHeader& header() const override { return header_; }
  bool next(TraceEvent& e) override;
  ReadProgress progress() const override;

 private:
  /// A frame kept for `repeat` lines (the last kMaxRepeatGroup frames).
  struct Kept {
    Tick tick = 0, duration = 0;
    std::vector<std::uint8_t> mosi, miso, known;
  };
  bool next_line(std::string_view& line);
  bool parse_line(std::string_view line, TraceEvent& e);
  void parse_repeat(std::string_view rest, std::string_view time_tok, Tick tick);
  void keep_frame(const TraceEvent& e);
  void next_repetition(TraceEvent& e);
  void read_header();
  [[noreturn]] void fail(const std::string& message) const;

  TraceHeader header_;
  std::unique_ptr<TraceFileReader> file_;
  std::vector<char> buffer_;
  std::string_view text_;     // unread text (whole input in string mode, buffered part in file mode)
  bool eof_ = false;
  bool last_line_unterminated_ = false;
  std::uint64_t line_no_ = 0;
  bool have_pending_ = false;  // read_header() stopped at the first event
  TraceEvent pending_;
  bool any_event_ = false;
  Tick last_tick_ = 0;
  Tick last_frame_end_ = 0;
  std::vector<std::uint8_t> mosi_, miso_, known_;
  std::string axis_text_;  // an axis event's spec
  TraceWire wire_;         // the last `wire` line's settings: every frame from it on has them
  // `repeat` lines: the last frames (a ring), and the repetition being handed out.
  std::vector<Kept> kept_;
  std::size_t kept_next_ = 0;   // ring slot the next frame goes to
  std::size_t kept_count_ = 0;  // frames in the ring since the last pin/fault event
  std::size_t group_ = 0;       // frames in the group being repeated (0 = none)
  std::size_t group_index_ = 0; // next frame of the current repetition
  std::uint64_t repeat_count_ = 0, repeat_done_ = 0;
  Tick repeat_period_ = 0;
  std::uint64_t repeat_line_ = 0;
  // The work bound: frames handed out or promised by the `repeat` lines read so far.
  std::uint64_t max_frames_ = kDefaultMaxTraceFrames;
  std::uint64_t frames_ = 0;
};

/// Choices for a NativeTraceWriter.
struct NativeWriteOptions {
  /// Hand every event to the OS before write() returns (a plain file: each line; a gzip file:
  /// a flush point by size and time, TraceFlushPolicy), so a process that is killed leaves
  /// a trace that ends with the last event written (gzip: the last flush point).
  bool flush_each_event = true;
  /// Collapse a group of up to kMaxRepeatGroup frames that repeats with a constant period
  /// (same bytes, same durations) into one `repeat` line. Lossless: reading gives every frame.
  bool compact = true;
};

/// The most repetitions an open `repeat` line (the count a recording updates in place) holds:
/// its count field is 6 characters wide. A longer run goes on with frame lines and a new run.
inline constexpr std::uint64_t kMaxOpenRepeatCount = 999'999;

/// Writes a native trace (version 3): one line per event, or per run of repeated frames (see
/// NativeWriteOptions), and a `wire` line before a frame whose TraceEvent::wire differs from the
/// frame's before it (an unknown wire counts as its defaults: a trace of byte-face frames has
/// none). A file whose name ends in ".gz" is gzip-compressed.
///
/// What a killed process leaves (flush_each_event): in an output that can be rewritten (a plain
/// file), every event written, including the repetitions of a run in progress: a run is an
/// open `repeat` line whose count is replaced in place as repetitions complete, the frames of
/// an unfinished repetition following it as frame lines; in a gzip file, every event up to the
/// last flush point (TraceFlushPolicy), where a run in progress is written as a closed `repeat`
/// line (an output without a flush policy: at least every 1024 repetitions or every second of
/// trace time).
class NativeTraceWriter final : public TraceSink {
 public:
  /// Creates or truncates `path`. Throws std::runtime_error when it cannot.
  explicit NativeTraceWriter(const std::string& path, bool flush_each_event = true);
  NativeTraceWriter(const std::string& path, NativeWriteOptions options);
  /// Writes to `out` (flushed after every event when `flush_each_event`). A write error is a
  /// std::runtime_error of one line naming where the trace was going: `name` ("standard
  /// output", a file's path), and the reason when the system gave one.
  explicit NativeTraceWriter(std::ostream& out, bool flush_each_event = true);
  NativeTraceWriter(std::ostream& out, NativeWriteOptions options, std::string name = "the output stream");
  /// Writes to `output` (a front's own: a memory-mapped file, a file with its flush policy).
  explicit NativeTraceWriter(std::unique_ptr<TraceOutput> output, NativeWriteOptions options = {});
  /// Writes what is pending (a run in progress) and closes; errors here are lost: call finish().
  ~NativeTraceWriter() override;
  NativeTraceWriter(const NativeTraceWriter&) = delete;
  NativeTraceWriter& operator=(const NativeTraceWriter&) = delete;

  void write_header(const TraceHeader& header) override;
  void write(const TraceEvent& e) override;
  /// Writes what is pending and closes the file (the gzip trailer). Throws on a write error.
  void finish();
  /// Hands what the output holds to the OS if its flush policy's time has come (call it while
  /// a recording is quiet). Throws on a write error.
  void flush_if_due();
  /// Stops without writing anything more, now or when destroyed (a forked child's copy of a
  /// recording its parent goes on writing).
  void abandon();

  /// One event as its native line, without the newline.
  static std::string format_event(const TraceEvent& e);
  /// The same, appended to `out`.
  static void append_event(std::string& out, const TraceEvent& e);
  /// The line without its time (" frame 1.75us D0 | 00"), appended to `out`.
  static void append_event_body(std::string& out, const TraceEvent& e);
  /// The `repeat` line, without the newline, saying that the last `group` frames (the last
  /// of them at `last_frame`) repeat `count` times, each repetition `period` after the one before.
  static std::string format_repeat(Tick last_frame, std::size_t group, std::uint64_t count, Tick period);

 private:
  struct Held {
    Tick tick = 0, duration = 0;
    bool has_miso = false;
    std::vector<std::uint8_t> mosi, miso, known;
    std::uint64_t print = 0;  // a hash of what same_bytes compares: unequal prints, different frames
    void assign(const TraceEvent& e);
    bool same_bytes(const Held& o) const;
    bool same_bytes(const TraceEvent& e) const;
    TraceEvent event() const;
  };
  void put(const std::string& text);
  void write_line(const TraceEvent& e);
  void frame(const TraceEvent& e);
  void write_partial_line(const TraceEvent& e);
  void frame_line(const TraceEvent& e);
  void look_for_run();
  void end_run();
  /// The run's repeat line for the repetitions since the last one; `progress_only` when the run
  /// goes on (a checkpoint), not when it ends.
  void write_repeat_line(bool progress_only = false);
  void write_open_repeat_line();
  bool checkpoint_due() const;
  bool open_runs() const { return open_runs_; }
  const std::string& name() const;

  std::unique_ptr<TraceOutput> out_;
  NativeWriteOptions options_;
  bool open_runs_ = false;  // out_ rewritable and every event flushed: open repeat lines
  bool header_written_ = false;
  bool finished_ = false;
  bool abandoned_ = false;
  std::string line_;
  // Compaction: the frames written since the last pin/fault event (at most 3 groups' worth)...
  std::vector<Held> recent_;     // a ring once full: the oldest is recent_[recent_first_]
  std::size_t recent_first_ = 0;
  Held& recent(std::size_t i) {
    const std::size_t at = recent_first_ + i;  // i < recent_.size(): one wrap at most
    return recent_[at < recent_.size() ? at : at - recent_.size()];
  }
  /// Makes the ring a plain vector again, oldest first (before the rare edits of recent_).
  void straighten_recent();
  // For each group size k: how many of the latest recent frames repeat the frame k before them
  // (same bytes) at one and the same distance in time, and that distance. A run of k frames
  // repeated `copies` times is there when the streak reaches (copies - 1) * k.
  // The streaks go by the frames' prints; look_for_run compares the bytes of a streak that is
  // long enough before it starts a run.
  std::array<std::uint64_t, kMaxRepeatGroup + 1> streak_{};  // meaningful only where live_ has bit k
  std::array<Tick, kMaxRepeatGroup + 1> streak_period_{};
  std::uint32_t live_ = 0;   // bit k: group size k has a streak
  std::uint32_t ready_ = 0;  // bit k: group size k's streak is long enough for a run (look_for_run)
  // The prints and ticks of the last kMaxRepeatGroup frames noted, newest first from
  // history_at_: each is stored twice (at j and j + kMaxRepeatGroup) so that the k-th latest
  // is at history_at_ + k - 1 without wrapping. history_size_ of them are valid.
  std::array<std::uint64_t, 2 * kMaxRepeatGroup> history_print_{};
  std::array<Tick, 2 * kMaxRepeatGroup> history_tick_{};
  std::size_t history_at_ = 0, history_size_ = 0;
  void note_recent(std::size_t i);
  void recount_recent();
  void forget_recent();
  // ...and the run being collapsed: the group (its last complete repetition), the period,
  // the repetitions not yet in the file (closed lines) or in its count (open lines) and the
  // frames of the repetition under way.
  bool in_run_ = false;
  std::size_t run_group_ = 0;
  Tick run_period_ = 0;
  std::vector<Held> run_;
  std::size_t partial_ = 0;  // frames of the repetition under way (the group's first ones, a period on)
  std::vector<std::string> run_bodies_;  // open runs: each group frame's line after its time, with the newline
  std::uint64_t line_count_ = 0;  // repetitions the run's repeat line stands for
  std::uint64_t run_repetitions_ = 0;  // repetitions of the run so far, on every line
  Tick line_base_ = 0;            // tick of the group's last frame as the file has it before that line
  std::uint64_t count_offset_ = 0;  // open line: where its count field starts in the output
  std::uint64_t count_word_ = 0;  // open line: its count field and newline as written, in memory order
  Tick checkpoint_tick_ = 0;
  TraceWire wire_;  // the wire the file's frames have now (the last `wire` line written)
  void write_wire_line(const TraceEvent& frame);
};

/// A native trace as text (header and every event; runs collapsed when `compact`).
std::string to_native_text(const Trace& trace, bool compact = false);

/// Reads a whole native trace into memory (at most `max_frames` frames; 0: no limit).
Trace read_native_trace(std::string_view text, const std::string& name,
                        std::uint64_t max_frames = kDefaultMaxTraceFrames);

}  // namespace l6470emu
