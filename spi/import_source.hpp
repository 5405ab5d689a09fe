// The text an importer reads (internal to spi/): from memory, or streamed from a file (plain or
// gzip) a chunk at a time, so that a capture is never held whole in memory. Lines with their
// numbers, at most kMaxTraceLineBytes long; a look for marker strings over the whole text; a
// second pass from the start. What the text means is the importers' business.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "spi/trace.hpp"
#include "spi/trace_import.hpp"

namespace l6470emu {

class TraceFileReader;

namespace detail {

/// A capture's text, line by line, from memory or from a file.
class ImportSource {
 public:
  /// Over `text` (kept by reference: it must outlive the source), called `name` in messages.
  ImportSource(std::string_view text, std::string name);
  /// Over the file at `path` (gzip-compressed when it starts with the gzip magic), called `path`
  /// in messages. Throws TraceError when it cannot be opened.
  explicit ImportSource(const std::string& path);
  ~ImportSource();
  ImportSource(const ImportSource&) = delete;
  ImportSource& operator=(const ImportSource&) = delete;

  const std::string& name() const { return name_; }

  /// The next line (without '\n' and a '\r' before it; a UTF-8 byte order mark at the start of
  /// the text is dropped); false at the end. The view stays valid until the next call. Throws
  /// TraceError for a line longer than kMaxTraceLineBytes and for damaged gzip data.
  bool next(std::string_view& line);
  /// The number of the line last returned (from 1).
  std::uint64_t number() const { return number_; }
  /// Whether the line last returned ended the text without a newline.
  bool unterminated() const { return unterminated_; }

  /// The next stretch of raw text (no lines: for a JSON reader), at most one buffer-full;
  /// false at the end. Not to be mixed with next() in one pass. Throws TraceError for damaged
  /// gzip data (naming the byte offset, not a line).
  bool next_chunk(std::string_view& chunk);

  /// Back to the first line (a file is opened again).
  void rewind();
  /// For each of `needles`, whether it occurs anywhere in the text: one pass over it (stopping
  /// early once every needle was seen), then back to the first line.
  std::vector<bool> contains(std::span<const std::string_view> needles);
  /// Whether `needle` occurs anywhere in the text (see contains()).
  bool contains(std::string_view needle);

  /// How far reading has come, in bytes of the file on disk (or of the text).
  ReadProgress progress() const;
  /// Tells `report` progress() every few thousand lines or chunks (empty: nobody).
  void on_progress(std::function<void(const ReadProgress&)> report) { report_ = std::move(report); }

 private:
  /// Reads more of the file behind what is unread; false at its end.
  bool fill();

  std::string name_;
  std::string path_;           // empty: from memory
  std::string_view text_;      // from memory: the whole text
  std::unique_ptr<TraceFileReader> file_;
  std::vector<char> buffer_;
  std::size_t begin_ = 0, end_ = 0;  // the unread part of buffer_ (file) or text_ (memory)
  bool eof_ = false;
  bool at_start_ = true;
  std::uint64_t number_ = 0;
  bool unterminated_ = false;
  std::function<void(const ReadProgress&)> report_;
};

/// The importers over a source (the string and file front ends in trace_import.hpp call them).
Trace import_saleae(ImportSource& source, const ImportOptions& options);
Trace import_umockdev(ImportSource& source, const ImportOptions& options);
Trace import_ftrace(ImportSource& source, const ImportOptions& options);
Trace import_sigrok(ImportSource& source, const ImportOptions& options);

}  // namespace detail
}  // namespace l6470emu
