// Where a native trace's text goes: an output the writer appends whole lines to, which may let
// it replace the end of what it wrote (a run's `repeat` count) and decides when what it holds
// is handed to the OS. Files (plain or gzip, through stdio and zlib) and streams here; a front
// may bring its own (linux/'s memory-mapped recording file). No trace syntax here.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace l6470emu {

/// When a trace file hands what it holds to the OS (what a killed process leaves).
struct TraceFlushPolicy {
  /// Plain files: at the end of every event (each line is in the file before the event returns).
  bool plain_every_event = true;
  /// gzip files: a flush point once this many bytes of text came since the last one...
  std::size_t gzip_bytes = 64 * 1024;
  /// ...or once this much host time passed since the last one (checked at the end of each event
  /// and by flush_if_due()); needs `clock`.
  std::int64_t gzip_interval_ns = 200'000'000;
  /// While all that is new is the progress of one run of repeated frames (its `repeat` line
  /// written at a flush point), the interval doubles at each flush up to this, and drops back to
  /// gzip_interval_ns with anything else: an unchanging poll loop costs a line and a flush
  /// marker per 12.8 s instead of per 200 ms (which made a long run's .gz twice the size gzip -6
  /// gives its plain trace), and a kill loses at most that much of it.
  std::int64_t gzip_quiet_interval_ns = 12'800'000'000;
  /// The host's monotonic clock in ns, for gzip_interval_ns; empty = by size only.
  std::function<std::int64_t()> clock;
};

/// The bytes of a trace being written. Not thread-safe.
class TraceOutput {
 public:
  virtual ~TraceOutput() = default;
  /// Appends `text` (whole lines). Throws std::runtime_error (one line naming the output) on failure.
  virtual void append(std::string_view text) = 0;
  /// The same, for a line that only brings a run of repeated frames up to date (a `repeat`
  /// line written at a flush point): an output may flush such news less often (TraceFlushPolicy).
  virtual void append_run_progress(std::string_view text) { append(text); }
  /// The end of one event: what the output holds is handed to the OS as its policy says.
  virtual void event_end() {}
  /// Hands what is held to the OS if the policy's time has come (a quiet recording).
  virtual void flush_if_due() {}
  /// Whether what is held, with a run's progress appended (append_run_progress), would go to the
  /// OS now, by the output's own flush policy (a gzip recording's size and time): a writer
  /// holding back a run's repeat line writes it only then, so that no flush leaves it out and no
  /// line is written that no flush needs. nullopt: the output has no such policy (the writer
  /// keeps its own checkpoints).
  virtual std::optional<bool> flush_due() const { return std::nullopt; }
  /// Bytes appended so far, after replacements (where the next append goes).
  virtual std::uint64_t size() const = 0;
  /// Whether replace_tail works (plain files; not gzip or streams).
  virtual bool rewritable() const { return false; }
  /// Replaces everything from `offset` (at most size()) on with `text`; the output then ends
  /// after it. The change is made so that a process killed during it leaves either the old or
  /// the new bytes: every output promises it for a `text` of at most 7 bytes that starts at an
  /// offset of 8k..8k+7 and ends before 8(k+1) (the count of an open `repeat` line).
  virtual void replace_tail(std::uint64_t offset, std::string_view text);
  /// Finishes the output (what is held, the gzip trailer, the file's final length). Throws on
  /// failure. Idempotent.
  virtual void close() = 0;
  /// Gives up without writing anything more (a forked child's copy of its parent's recording:
  /// the parent goes on writing the file).
  virtual void abandon() {}
  /// What the output is called in messages (a file's path, "standard output").
  virtual const std::string& name() const = 0;
};

/// A file through stdio (plain: replace_tail by pwrite and ftruncate) or zlib (a name ending in
/// ".gz"), flushed as `policy` says. Throws std::runtime_error when `path` cannot be created.
std::unique_ptr<TraceOutput> open_trace_file_output(const std::string& path, TraceFlushPolicy policy = {});

/// A stream (not rewritable), flushed at the end of every event when `flush_each_event`.
std::unique_ptr<TraceOutput> stream_trace_output(std::ostream& out, std::string name, bool flush_each_event);

}  // namespace l6470emu
