// Linux ftrace text (tracefs "trace" file or `trace-cmd report`) with the spi events of
// include/trace/events/spi.h: spi_transfer_start/stop "spiB.C <xfer> len=N tx=[..] rx=[..]",
// spi_set_cs "spiB.C activate|deactivate", spi_message_start/done. Bytes come from
// spi_transfer_stop (rx is only valid there); CS frames from spi_set_cs when traced. Read a
// line at a time (a file is streamed, never held whole) after a look for the event names.
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

enum class Event { none, transfer_start, transfer_stop, set_cs, message_start, message_done };

struct Parsed {
  Event event = Event::none;
  SourceTime time;
  std::string_view device;
  std::string_view rest;  // after the device
};

std::string_view token(std::string_view& rest) {
  std::size_t i = 0;
  while (i < rest.size() && (rest[i] == ' ' || rest[i] == '\t')) ++i;
  std::size_t j = i;
  while (j < rest.size() && rest[j] != ' ' && rest[j] != '\t') ++j;
  const std::string_view t = rest.substr(i, j - i);
  rest.remove_prefix(j);
  return t;
}

class FtraceImporter {
 public:
  FtraceImporter(ImportSource& source, const ImportOptions& options)
      : source_(source), name_(source.name()), options_(options), frames_(trace_, name_, options.max_frames) {}

  Trace run() {
    trace_.header.name = name_;
    trace_.header.format = "ftrace";
    const std::string_view events[] = {"spi_set_cs:", "spi_transfer_stop:", "spi_transfer_start:"};
    const std::vector<bool> found = source_.contains(events);
    const bool has_cs = found[0], has_stop = found[1], has_start = found[2];
    if (!has_stop && !has_start)
      throw TraceError(name_, 0, "no spi_transfer_start/stop events (record with: trace-cmd record -e spi, or "
                                 "echo 1 > /sys/kernel/tracing/events/spi/enable)");
    data_event_ = has_stop ? Event::transfer_stop : Event::transfer_start;
    if (!has_stop) trace_.header.notes.push_back("only spi_transfer_start events: MISO is unknown (rx is filled in at spi_transfer_stop)");
    framing_ = options_.ftrace_framing;
    if (framing_ == FtraceFraming::automatic) {
      framing_ = has_cs ? FtraceFraming::cs : FtraceFraming::transfer;
      if (!has_cs)
        trace_.header.notes.push_back(
            "no spi_set_cs events (enable spi:spi_set_cs, Linux 5.19+): each transfer is taken as its own CS frame");
    } else if (framing_ == FtraceFraming::cs && !has_cs) {
      throw TraceError(name_, 0, "CS framing asked for, but the file has no spi_set_cs events");
    }

    ImportSource& lines = source_;
    std::string_view line;
    bool any_time = false;
    SourceTime last_time;
    while (lines.next(line)) {
      if (line.empty() || line[0] == '#') continue;
      Parsed p;
      if (!parse(lines, line, p)) continue;
      if (!options_.select.empty()) {
        if (p.device != options_.select) continue;
      } else if (device_.empty()) {
        device_ = std::string(p.device);
      } else if (p.device != device_) {
        fail(lines, "events of several SPI devices (" + printable(device_) + " and " + printable(p.device) +
                        "): choose one with --select");
      }
      if (any_time && p.time < last_time)
        fail(lines, "time " + FrameBuilder::seconds(p.time) + " s goes backwards (the previous event was at " +
                        FrameBuilder::seconds(last_time) + " s)");
      any_time = true;
      last_time = p.time;
      handle(lines, p);
    }
    if (open_) {
      // The capture ended inside a frame: keep what was seen.
      trace_.header.notes.push_back("the capture ends inside a CS frame (line " + std::to_string(open_line_) +
                                    "): that frame is kept up to its last transfer");
      close(last_time);
    }
    if (skipped_)
      trace_.header.notes.push_back(std::to_string(skipped_) +
                                    " transfers before the first CS activation skipped (the capture began inside a frame)");
    if (tx_missing_) trace_.header.notes.push_back("transfers without tx: MOSI taken as 0x00 (spidev clocks zeros out)");
    if (trace_.frame_count() == 0)
      throw TraceError(name_, 0, options_.select.empty() ? "no SPI transfers in the file"
                                                         : "no SPI transfers of " + options_.select + " in the file");
    return std::move(trace_);
  }

 private:
  [[noreturn]] void fail(const ImportSource& lines, const std::string& message) {
    std::string m = message;
    if (lines.unterminated()) m += " (the last line has no newline: truncated file?)";
    throw TraceError(name_, lines.number(), m);
  }

  /// Recognises an spi event line; false for anything else.
  bool parse(const ImportSource& lines, std::string_view line, Parsed& p) {
    static constexpr struct {
      std::string_view name;
      Event event;
    } kEvents[] = {{"spi_transfer_start:", Event::transfer_start},
                   {"spi_transfer_stop:", Event::transfer_stop},
                   {"spi_set_cs:", Event::set_cs},
                   {"spi_message_start:", Event::message_start},
                   {"spi_message_done:", Event::message_done}};
    std::size_t at = std::string_view::npos;
    for (const auto& k : kEvents) {
      const std::size_t i = line.find(k.name);
      if (i != std::string_view::npos && i >= 2 && line[i - 1] == ' ') {
        at = i;
        p.event = k.event;
        p.rest = line.substr(i + k.name.size());
        break;
      }
    }
    if (at == std::string_view::npos) return false;
    // The timestamp is the token right before the event name, ending in ':'.
    std::size_t end = at - 1;
    while (end > 0 && line[end - 1] == ' ') --end;
    if (end == 0 || line[end - 1] != ':') fail(lines, "no timestamp before the event name in " + quote(line));
    --end;
    std::size_t begin = end;
    while (begin > 0 && line[begin - 1] != ' ' && line[begin - 1] != '\t' && line[begin - 1] != ']') --begin;
    const std::string_view ts = line.substr(begin, end - begin);
    switch (parse_source_time_checked(ts, 0, p.time)) {
      case TimeParse::ok: break;
      case TimeParse::out_of_range: fail(lines, "timestamp " + quote(ts) + " is out of range");
      case TimeParse::malformed: fail(lines, "timestamp " + quote(ts) + " is not a time in seconds");
    }
    p.device = token(p.rest);
    if (p.device.rfind("spi", 0) != 0) fail(lines, "device " + quote(p.device) + " is not spiB.C");
    return true;
  }

  /// "tx=[21-00-ff]" → bytes; the list may be empty.
  void byte_list(const ImportSource& lines, std::string_view tok, std::string_view key, std::vector<std::uint8_t>& out) {
    out.clear();
    // key=[..]
    if (tok.size() < key.size() + 3 || tok.substr(0, key.size()) != key || tok[key.size()] != '=' ||
        tok[key.size() + 1] != '[' || tok.back() != ']')
      fail(lines, "expected " + std::string(key) + "=[..], found " + quote(tok));
    std::string_view list = tok.substr(key.size() + 2, tok.size() - key.size() - 3);
    while (!list.empty()) {
      if (list.size() < 2) fail(lines, std::string(key) + " byte " + quote(list) + " is not hex");
      const int hi = hex_digit_value(list[0]), lo = hex_digit_value(list[1]);
      if (hi < 0 || lo < 0) fail(lines, std::string(key) + " byte " + quote(list.substr(0, 2)) + " is not hex");
      out.push_back(static_cast<std::uint8_t>(hi << 4 | lo));
      list.remove_prefix(2);
      if (!list.empty()) {
        if (list[0] != '-' && list[0] != ' ') fail(lines, std::string(key) + " bytes must be separated by '-'");
        list.remove_prefix(1);
      }
    }
  }

  void open(const SourceTime& t, std::uint64_t line) {
    open_ = true;
    start_ = t;
    open_line_ = line;
    mosi_.clear();
    miso_.clear();
    known_.clear();
  }

  void close(const SourceTime& t) {
    bool any_known = false, all_known = true;
    for (auto k : known_) {
      any_known = any_known || k;
      all_known = all_known && k;
    }
    frames_.frame(start_, t, mosi_, any_known ? std::span<const std::uint8_t>(miso_) : std::span<const std::uint8_t>{},
                  any_known && !all_known ? std::span<const std::uint8_t>(known_) : std::span<const std::uint8_t>{},
                  open_line_);
    open_ = false;
  }

  void handle(const ImportSource& lines, const Parsed& p) {
    switch (p.event) {
      case Event::set_cs: {
        if (framing_ != FtraceFraming::cs) return;
        std::string_view rest = p.rest;
        std::string_view what = token(rest);
        if (!what.empty() && what.back() == ',') what.remove_suffix(1);
        if (what == "activate") {
          if (!open_) open(p.time, lines.number());
          seen_activate_ = true;
        } else if (what == "deactivate") {
          if (open_) close(p.time);
        } else {
          fail(lines, "spi_set_cs " + quote(what) + " is neither activate nor deactivate");
        }
        return;
      }
      case Event::message_start:
        if (framing_ == FtraceFraming::message) {
          if (open_) fail(lines, "spi_message_start while the message of line " + std::to_string(open_line_) + " is open");
          open(p.time, lines.number());
        }
        return;
      case Event::message_done:
        if (framing_ == FtraceFraming::message && open_) close(p.time);
        return;
      case Event::transfer_start:
      case Event::transfer_stop:
        break;
      case Event::none:
        return;
    }
    if (p.event == Event::transfer_start) {
      std::string_view rest = p.rest;
      start_xfer_ = std::string(token(rest));
      xfer_start_ = p.time;
      have_xfer_start_ = true;
      if (data_event_ != Event::transfer_start) return;
    }
    // The transfer's bytes.
    std::string_view rest = p.rest;
    const std::string_view xfer = token(rest);
    const std::string_view len_tok = token(rest);
    const std::string_view tx_tok = token(rest);
    const std::string_view rx_tok = token(rest);
    unsigned long len = 0;
    if (len_tok.rfind("len=", 0) != 0 || len_tok.size() == 4) fail(lines, "expected len=N, found " + quote(len_tok));
    for (char c : len_tok.substr(4)) {
      if (c < '0' || c > '9') fail(lines, "expected len=N, found " + quote(len_tok));
      len = len * 10 + static_cast<unsigned long>(c - '0');
      if (len > 1'000'000) fail(lines, "transfer length " + quote(len_tok.substr(4)) + " is too large");
    }
    byte_list(lines, tx_tok, "tx", tx_);
    byte_list(lines, rx_tok, "rx", rx_);
    if (p.event == Event::transfer_start) rx_.clear();  // rx is not filled in yet
    if (!tx_.empty() && !rx_.empty() && tx_.size() != rx_.size())
      fail(lines, "tx has " + std::to_string(tx_.size()) + " bytes but rx has " + std::to_string(rx_.size()));
    for (const auto* list : {&tx_, &rx_})
      if (!list->empty() && list->size() != len) {
        if (len > 64 && list->size() == 64)
          fail(lines, "transfer of " + std::to_string(len) +
                          " bytes: the kernel prints at most 64 of them, so this trace cannot be replayed");
        fail(lines, std::string(list == &tx_ ? "tx" : "rx") + " has " + std::to_string(list->size()) +
                        " bytes but len=" + std::to_string(len));
      }
    if (tx_.empty() && len > 0) tx_missing_ = true;

    const SourceTime begin = have_xfer_start_ && xfer == start_xfer_ ? xfer_start_ : p.time;
    have_xfer_start_ = false;
    if (framing_ == FtraceFraming::transfer) {
      open(begin, lines.number());
    } else if (!open_) {
      if (framing_ == FtraceFraming::cs && !seen_activate_) {
        ++skipped_;
        return;
      }
      fail(lines, framing_ == FtraceFraming::cs ? "transfer while CS is not active (no spi_set_cs activate before it)"
                                                : "transfer outside an spi_message_start/done pair");
    }
    if (mosi_.size() + len > kMaxTraceFrameBytes)
      fail(lines, frame_too_long(mosi_.size() + len) + " (the frame of line " + std::to_string(open_line_) + ")");
    for (std::size_t i = 0; i < len; ++i) {
      mosi_.push_back(tx_.empty() ? 0x00 : tx_[i]);
      miso_.push_back(rx_.empty() ? 0x00 : rx_[i]);
      known_.push_back(rx_.empty() ? 0 : 1);
    }
    if (framing_ == FtraceFraming::transfer) close(p.time);
  }

  ImportSource& source_;
  const std::string& name_;
  const ImportOptions& options_;
  Trace trace_;
  FrameBuilder frames_;
  FtraceFraming framing_ = FtraceFraming::automatic;
  Event data_event_ = Event::transfer_stop;
  std::string device_;
  bool open_ = false, seen_activate_ = false, tx_missing_ = false, have_xfer_start_ = false;
  std::uint64_t open_line_ = 0, skipped_ = 0;
  SourceTime start_, xfer_start_;
  std::string start_xfer_;
  std::vector<std::uint8_t> mosi_, miso_, known_, tx_, rx_;
};

}  // namespace

Trace detail::import_ftrace(ImportSource& source, const ImportOptions& options) {
  return FtraceImporter(source, options).run();
}

}  // namespace l6470emu
