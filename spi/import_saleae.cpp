// Saleae Logic SPI analyzer exports: Logic 2's data table (name,type,start_time,duration,
// "mosi","miso" with enable/result/disable rows; older 2.x without duration) and Logic 1.x
// (Time [s],Packet ID,MOSI,MISO). Read a line at a time (a file is streamed, never held whole),
// one pass and a look for enable rows, no allocation per row.
#include <algorithm>
#include <cctype>
#include <vector>

#include "spi/import_source.hpp"
#include "spi/import_support.hpp"
#include "spi/trace_import.hpp"

namespace l6470emu {
namespace {

using detail::FrameBuilder;
using detail::ImportSource;
using detail::printable;
using detail::quote;

/// Splits a CSV line into `fields` (outer quotes removed); false on an unterminated quote.
bool split_csv(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  std::size_t i = 0;
  const std::size_t n = line.size();
  for (;;) {
    if (i < n && line[i] == '"') {
      // Quoted field; "" inside stands for one quote (kept doubled in the view).
      std::size_t j = i + 1;
      for (;;) {
        const void* q = std::memchr(line.data() + j, '"', n - j);
        if (q == nullptr) return false;
        j = static_cast<std::size_t>(static_cast<const char*>(q) - line.data());
        if (j + 1 < n && line[j + 1] == '"') {
          j += 2;
          continue;
        }
        break;
      }
      fields.push_back(line.substr(i + 1, j - i - 1));
      i = j + 1;
      while (i < n && line[i] == ' ') ++i;
      if (i == n) return true;
      if (line[i] != ',') return false;
      ++i;
    } else {
      const void* c = std::memchr(line.data() + i, ',', n - i);
      if (c == nullptr) {
        fields.push_back(line.substr(i));
        return true;
      }
      const auto j = static_cast<std::size_t>(static_cast<const char*>(c) - line.data());
      fields.push_back(line.substr(i, j - i));
      i = j + 1;
    }
  }
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  // Trim spaces.
  while (!out.empty() && out.back() == ' ') out.pop_back();
  while (!out.empty() && out.front() == ' ') out.erase(out.begin());
  return out;
}

/// A byte as Saleae shows it: hex "0x21", decimal "33" or binary "0b00100001".
bool parse_value(std::string_view s, std::uint8_t& out) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  if (s.empty()) return false;
  unsigned v = 0;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    for (std::size_t i = 2; i < s.size(); ++i) {
      const int d = hex_digit_value(s[i]);
      if (d < 0) return false;
      v = v * 16 + static_cast<unsigned>(d);
      if (v > 0xFF) return false;
    }
  } else if (s.size() > 2 && s[0] == '0' && (s[1] == 'b' || s[1] == 'B')) {
    for (std::size_t i = 2; i < s.size(); ++i) {
      if (s[i] != '0' && s[i] != '1') return false;
      v = v * 2 + static_cast<unsigned>(s[i] - '0');
      if (v > 0xFF) return false;
    }
  } else {
    for (char c : s) {
      if (c < '0' || c > '9') return false;
      v = v * 10 + static_cast<unsigned>(c - '0');
      if (v > 0xFF) return false;
    }
  }
  out = static_cast<std::uint8_t>(v);
  return true;
}

class SaleaeImporter {
 public:
  SaleaeImporter(ImportSource& source, const ImportOptions& options)
      : source_(source), name_(source.name()), options_(options), frames_(trace_, name_, options.max_frames) {}

  Trace run() {
    trace_.header.name = name_;
    trace_.header.format = "saleae";
    ImportSource& lines = source_;  // a UTF-8 byte order mark is dropped by the source
    std::string_view line;
    // Header: the first non-empty line.
    while (lines.next(line) && line.empty()) {
    }
    if (lines.number() == 0 || line.empty()) throw TraceError(name_, 0, "empty file (expected a Saleae CSV export)");
    header_line_ = std::string(line);
    if (!split_csv(line, fields_)) fail(lines, "malformed CSV header");
    columns_ = fields_.size();
    for (std::size_t i = 0; i < fields_.size(); ++i) {
      const std::string h = lower(fields_[i]);
      if (h == "name") col_name_ = static_cast<int>(i);
      else if (h == "type") col_type_ = static_cast<int>(i);
      else if (h == "start_time") col_start_ = static_cast<int>(i);
      else if (h == "duration") col_duration_ = static_cast<int>(i);
      else if (h == "mosi") col_mosi_ = static_cast<int>(i);
      else if (h == "miso") col_miso_ = static_cast<int>(i);
      else if (h == "time [s]") col_time_ = static_cast<int>(i);
      else if (h == "packet id") col_packet_ = static_cast<int>(i);
    }
    const bool logic1 = col_time_ >= 0 && col_type_ < 0;
    if (!logic1 && (col_type_ < 0 || col_start_ < 0))
      fail(lines, "not a Saleae SPI analyzer export: the header " + quote(line) +
                      " lacks type and start_time (expected name,type,start_time,duration,\"mosi\",\"miso\")");
    if (col_mosi_ < 0)
      fail(lines, "no \"mosi\" column in the header " + quote(line) + " (export the SPI analyzer with MOSI enabled)");
    if (col_miso_ < 0) trace_.header.notes.push_back("no \"miso\" column: MISO bytes are unknown and not compared");
    if (logic1)
      run_logic1(lines);
    else
      run_logic2(lines);
    return std::move(trace_);
  }

 private:
  [[noreturn]] void fail(const ImportSource& lines, const std::string& message) {
    std::string m = message;
    if (lines.unterminated()) m += " (the last line has no newline: truncated file?)";
    throw TraceError(name_, lines.number(), m);
  }

  /// Splits a data row and checks its width.
  void row(const ImportSource& lines, std::string_view line) {
    if (!split_csv(line, fields_)) fail(lines, "unterminated quote in the row " + printable(line));
    if (fields_.size() != columns_)
      fail(lines, std::to_string(fields_.size()) + " fields, the header has " + std::to_string(columns_) + " (" +
                      printable(header_line_) + ")");
  }

  SourceTime time_field(const ImportSource& lines, int col, const char* what) {
    SourceTime t;
    const std::string_view text = fields_[static_cast<std::size_t>(col)];
    switch (parse_source_time_checked(text, 0, t)) {
      case TimeParse::ok: break;
      case TimeParse::out_of_range: fail(lines, std::string(what) + " " + quote(text) + " is out of range");
      case TimeParse::malformed: fail(lines, std::string(what) + " " + quote(text) + " is not a time in seconds");
    }
    return t;
  }

  /// The duration column: a time in seconds, not negative, at most 10^6 s (no CS frame or byte is longer).
  SourceTime duration_field(const ImportSource& lines) {
    const SourceTime d = time_field(lines, col_duration_, "duration");
    const std::string_view text = fields_[static_cast<std::size_t>(col_duration_)];
    if (d < SourceTime{}) fail(lines, "duration " + quote(text) + " is negative");
    if (d > SourceTime{1'000'000, 0}) fail(lines, "duration " + quote(text) + " is out of range (more than 10^6 s)");
    return d;
  }

  /// Appends the MOSI/MISO bytes of the current row to the frame being built.
  void take_bytes(const ImportSource& lines, std::uint64_t frame_line) {
    if (mosi_.size() >= kMaxTraceFrameBytes)
      fail(lines, frame_too_long(mosi_.size() + 1) + " (the frame of line " + std::to_string(frame_line) + ")");
    std::uint8_t b = 0;
    const std::string_view mosi = fields_[static_cast<std::size_t>(col_mosi_)];
    if (!parse_value(mosi, b))
      fail(lines, mosi.empty() ? std::string("MOSI is empty") : "MOSI " + quote(mosi) + " is not a byte");
    mosi_.push_back(b);
    if (col_miso_ < 0) return;
    const std::string_view miso = fields_[static_cast<std::size_t>(col_miso_)];
    if (miso.empty()) {
      miso_.push_back(0);
      known_.push_back(0);
      any_unknown_ = true;
      return;
    }
    if (!parse_value(miso, b)) fail(lines, "MISO " + quote(miso) + " is not a byte");
    miso_.push_back(b);
    known_.push_back(1);
  }

  void emit(const SourceTime& start, const SourceTime& end, std::uint64_t line) {
    const bool any_known = col_miso_ >= 0 && std::find(known_.begin(), known_.end(), 1) != known_.end();
    frames_.frame(start, end, mosi_, any_known ? std::span<const std::uint8_t>(miso_) : std::span<const std::uint8_t>{},
                  any_known && any_unknown_ ? std::span<const std::uint8_t>(known_) : std::span<const std::uint8_t>{},
                  line);
    mosi_.clear();
    miso_.clear();
    known_.clear();
    any_unknown_ = false;
  }

  /// The file gave no frame: say why, naming the analyzers when --select matched none.
  [[noreturn]] void no_frames() const {
    if (!options_.select.empty() && !other_names_.empty()) {
      std::string names;
      for (const std::string& n : other_names_) names += (names.empty() ? "" : ", ") + quote(n);
      throw TraceError(name_, 0, "no rows of an analyzer called " + quote(options_.select) + " (the file has " + names +
                                     "): see --select");
    }
    throw TraceError(name_, 0, "no SPI frames in the file");
  }

  bool selected(const ImportSource& lines) {
    if (col_name_ < 0) return true;
    const std::string_view n = fields_[static_cast<std::size_t>(col_name_)];
    if (!options_.select.empty()) {
      if (n == options_.select) return true;
      if (other_names_.size() < 8 && std::find(other_names_.begin(), other_names_.end(), n) == other_names_.end())
        other_names_.emplace_back(n);
      return false;
    }
    if (analyzer_.empty()) {
      analyzer_ = std::string(n);
      return true;
    }
    if (n != analyzer_)
      fail(lines, "rows of several analyzers (" + quote(analyzer_) + " and " + quote(n) +
                      "): choose one with --select NAME");
    return true;
  }

  void run_logic2(ImportSource& lines) {
    // Does the export have CS (enable/disable rows) at all? Without an Enable channel
    // every byte is taken as its own frame.
    // (A look through the whole file, then back to the header, which is read again.)
    const std::string_view enable_rows[] = {"\"enable\"", ",enable,"};
    const std::vector<bool> found = lines.contains(enable_rows);
    const bool has_enable = found[0] || found[1];
    std::string_view line;
    while (lines.next(line) && line.empty()) {
    }
    if (!has_enable)
      trace_.header.notes.push_back(
          "no enable/disable rows (the analyzer had no Enable channel): each byte is taken as its own CS frame");
    bool open = false, seen_enable = false;
    std::uint64_t open_line = 0, skipped = 0, errors = 0;
    SourceTime start;
    while (lines.next(line)) {
      if (line.empty()) continue;
      row(lines, line);
      if (!selected(lines)) continue;
      const std::string_view type = fields_[static_cast<std::size_t>(col_type_)];
      const SourceTime t = time_field(lines, col_start_, "start_time");
      SourceTime duration;
      if (col_duration_ >= 0) duration = duration_field(lines);
      if (type == "result") {
        if (!has_enable) {
          take_bytes(lines, lines.number());
          SourceTime end = t;
          end.picoseconds += duration.picoseconds;
          end.seconds += duration.seconds + end.picoseconds / 1'000'000'000'000;
          end.picoseconds %= 1'000'000'000'000;
          emit(t, end, lines.number());
          continue;
        }
        if (!open) {
          if (!seen_enable) {
            ++skipped;  // the capture began inside a frame
            continue;
          }
          fail(lines, "result row outside a CS frame (no enable row since the disable before)");
        }
        if (t < start) fail(lines, "time " + FrameBuilder::seconds(t) + " s goes backwards (the frame began at " +
                                       FrameBuilder::seconds(start) + " s)");
        take_bytes(lines, open_line);
      } else if (type == "enable") {
        if (open) fail(lines, "enable row while the frame opened on line " + std::to_string(open_line) + " is still open");
        open = true;
        seen_enable = true;
        open_line = lines.number();
        start = t;
      } else if (type == "disable") {
        if (!open) {
          if (!seen_enable) {
            ++skipped;
            continue;
          }
          fail(lines, "disable row without an enable row before it");
        }
        if (t < start) fail(lines, "time " + FrameBuilder::seconds(t) + " s goes backwards (the frame began at " +
                                       FrameBuilder::seconds(start) + " s)");
        emit(start, t, open_line);
        open = false;
      } else if (type == "error") {
        ++errors;
      } else {
        fail(lines, "unknown row type " + quote(type) + " (enable, result, disable or error)");
      }
    }
    if (open)
      throw TraceError(name_, open_line,
                       "this enable row has no disable row after it: truncated file? (cut the capture before this row)");
    if (skipped)
      trace_.header.notes.push_back(std::to_string(skipped) +
                                    " rows before the first enable row skipped (the capture began inside a CS frame)");
    if (errors)
      trace_.header.notes.push_back(std::to_string(errors) +
                                    " \"error\" rows ignored (the analyzer saw the clock in the wrong state at CS)");
    if (trace_.frame_count() == 0) no_frames();
  }

  void run_logic1(ImportSource& lines) {
    bool open = false;
    std::string packet;
    SourceTime start, last;
    std::uint64_t open_line = 0;
    std::string_view line;
    while (lines.next(line)) {
      if (line.empty()) continue;
      row(lines, line);
      const SourceTime t = time_field(lines, col_time_, "time");
      const std::string_view id = col_packet_ >= 0 ? fields_[static_cast<std::size_t>(col_packet_)] : std::string_view{};
      if (open && (id.empty() || id != packet)) {
        emit(start, last, open_line);
        open = false;
      }
      if (open && t < last) fail(lines, "time " + FrameBuilder::seconds(t) + " s goes backwards");
      if (!open) {
        open = true;
        start = t;
        packet = std::string(id);
        open_line = lines.number();
      }
      take_bytes(lines, open_line);
      last = t;
    }
    if (open) emit(start, last, open_line);
    trace_.header.notes.push_back(
        "Logic 1.x export: CS frames from Packet ID, frame times from the first and last byte");
    if (trace_.frame_count() == 0) no_frames();
  }

  ImportSource& source_;
  const std::string& name_;
  const ImportOptions& options_;
  Trace trace_;
  FrameBuilder frames_;
  std::string header_line_;
  std::size_t columns_ = 0;
  int col_name_ = -1, col_type_ = -1, col_start_ = -1, col_duration_ = -1, col_mosi_ = -1, col_miso_ = -1;
  int col_time_ = -1, col_packet_ = -1;
  std::string analyzer_;
  std::vector<std::string> other_names_;  // with --select: the other analyzers seen (a few)
  std::vector<std::string_view> fields_;
  std::vector<std::uint8_t> mosi_, miso_, known_;
  bool any_unknown_ = false;
};

}  // namespace

Trace detail::import_saleae(ImportSource& source, const ImportOptions& options) {
  return SaleaeImporter(source, options).run();
}

}  // namespace l6470emu
