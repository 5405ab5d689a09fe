// umockdev SPI .ioctl recordings (umockdev-spi.vala): "@DEV /dev/spidevB.C (SPI)", then
// transfers "T" (CS asserted anew) or "C" (CS kept asserted) with "W hex" / "R hex" parts.
// The format has no times; frames are given the duration of their bytes on the bus. Read a line
// at a time (a file is streamed, never held whole).
#include <vector>

#include "spi/import_source.hpp"
#include "spi/import_support.hpp"
#include "spi/message.hpp"
#include "spi/trace_import.hpp"

namespace l6470emu {
namespace {

using detail::FrameBuilder;
using detail::ImportSource;
using detail::quote;

class UmockdevImporter {
 public:
  UmockdevImporter(ImportSource& source, const ImportOptions& options)
      : source_(source), name_(source.name()), options_(options) {}

  Trace run() {
    trace_.header.name = name_;
    trace_.header.format = "umockdev";
    ImportSource& lines = source_;
    std::string_view line;
    bool saw_dev = false;
    while (lines.next(line)) {
      if (line.empty() || line[0] == '#') continue;
      if (line[0] == '@') {
        if (line.rfind("@DEV ", 0) == 0 && line.find("(SPI)") == std::string_view::npos)
          fail(lines, "device " + quote(line.substr(5)) + " is not recorded as SPI (no \"(SPI)\" after @DEV)");
        saw_dev = true;
        continue;
      }
      if (line.size() < 3 || line[2] != ' ')
        fail(lines, "malformed transfer line " + quote(line) + " (expected \"TW hex\", \"CR hex\" or \" R hex\")");
      const char start = line[0], dir = line[1];
      if (start == 'T' || start == 'C') {
        if (start == 'C' && !in_chunk_) fail(lines, "\"C\" (CS kept asserted) without a transfer before it");
        close_chunk(lines);
        if (start == 'T') close_frame(lines.number());
        in_chunk_ = true;
        if (frame_line_ == 0) frame_line_ = lines.number();
      } else if (start != ' ') {
        fail(lines, "transfer line must start with T, C or a space, not " + quote(line.substr(0, 1)));
      } else if (!in_chunk_) {
        fail(lines, "continuation line without a transfer before it");
      }
      std::vector<std::uint8_t>* dst = nullptr;
      if (dir == 'W') dst = &chunk_w_;
      else if (dir == 'R') dst = &chunk_r_;
      else fail(lines, "transfer direction " + quote(line.substr(1, 1)) + " is not W or R");
      bool& seen = dir == 'W' ? has_w_ : has_r_;
      if (seen) fail(lines, std::string("a second ") + dir + " part in one transfer");
      seen = true;
      std::string_view hex = line.substr(3);
      while (!hex.empty() && (hex.back() == ' ' || hex.back() == '\t')) hex.remove_suffix(1);
      if (hex.size() % 2 != 0) fail(lines, "odd number of hex digits in " + quote(hex));
      if (mosi_.size() + dst->size() + hex.size() / 2 > kMaxTraceFrameBytes)
        fail(lines, frame_too_long(mosi_.size() + dst->size() + hex.size() / 2) + " (the frame of line " +
                        std::to_string(frame_line_) + ")");
      for (std::size_t i = 0; i < hex.size(); i += 2) {
        const int hi = hex_digit_value(hex[i]), lo = hex_digit_value(hex[i + 1]);
        if (hi < 0 || lo < 0)
          fail(lines, std::string(dir == 'W' ? "W" : "R") + " byte " + quote(hex.substr(i, 2)) + " is not hex");
        dst->push_back(static_cast<std::uint8_t>(hi << 4 | lo));
      }
      if (has_w_ && has_r_ && chunk_w_.size() != chunk_r_.size())
        fail(lines, "W has " + std::to_string(chunk_w_.size()) + " bytes but R has " + std::to_string(chunk_r_.size()) +
                        " (read and write of one transfer must have the same length)");
    }
    close_chunk(lines);
    close_frame(lines.number());
    if (!saw_dev) trace_.header.notes.push_back("no @DEV line (not checked as an SPI recording)");
    const std::uint32_t hz = options_.umockdev_speed_hz;
    const std::string speed = hz % 1'000'000 == 0 ? std::to_string(hz / 1'000'000) + " MHz"
                              : hz % 1000 == 0    ? std::to_string(hz / 1000) + " kHz"
                                                  : std::to_string(hz) + " Hz";
    trace_.header.notes.push_back("umockdev recordings carry no times: frames follow each other as on a " + speed +
                                  " bus with 1 us CS high, so a host's waits are not replayed");
    if (rx_only_)
      trace_.header.notes.push_back("read-only transfers: MOSI taken as 0x00 (spidev clocks zeros out with no tx_buf)");
    if (trace_.frame_count() == 0) throw TraceError(name_, 0, "no SPI transfers in the file");
    return std::move(trace_);
  }

 private:
  [[noreturn]] void fail(const ImportSource& lines, const std::string& message) {
    std::string m = message;
    if (lines.unterminated()) m += " (the last line has no newline: truncated file?)";
    throw TraceError(name_, lines.number(), m);
  }

  void close_chunk(const ImportSource& lines) {
    if (!in_chunk_) return;
    if (!has_w_ && !has_r_) fail(lines, "transfer without W or R bytes");
    const std::size_t n = has_w_ ? chunk_w_.size() : chunk_r_.size();
    for (std::size_t i = 0; i < n; ++i) {
      mosi_.push_back(has_w_ ? chunk_w_[i] : 0x00);
      miso_.push_back(has_r_ ? chunk_r_[i] : 0x00);
      known_.push_back(has_r_ ? 1 : 0);
    }
    if (!has_w_) rx_only_ = true;
    chunk_w_.clear();
    chunk_r_.clear();
    has_w_ = has_r_ = false;
    in_chunk_ = false;
  }

  /// Ends the frame under way; `line` is where the next one begins (for the frame bound).
  void close_frame(std::uint64_t line) {
    if (frame_line_ == 0) return;
    FrameBuilder::check_frame_count(trace_, name_, options_.max_frames, frame_line_ != 0 ? frame_line_ : line);
    bool any_known = false, all_known = true;
    for (auto k : known_) {
      any_known = any_known || k;
      all_known = all_known && k;
    }
    const BusTiming timing{};
    TraceEvent e;
    e.kind = TraceEventKind::frame;
    e.tick = now_;
    e.duration = transfer_ticks(1, options_.umockdev_speed_hz) * mosi_.size();
    e.mosi = mosi_;
    if (any_known) e.miso = miso_;
    if (any_known && !all_known) e.miso_known = known_;
    e.line = frame_line_;
    trace_.write(e);
    now_ = e.end() + timing.cs_high_ticks;
    mosi_.clear();
    miso_.clear();
    known_.clear();
    frame_line_ = 0;
  }

  ImportSource& source_;
  const std::string& name_;
  const ImportOptions& options_;
  Trace trace_;
  std::vector<std::uint8_t> chunk_w_, chunk_r_, mosi_, miso_, known_;
  bool has_w_ = false, has_r_ = false, in_chunk_ = false, rx_only_ = false;
  std::uint64_t frame_line_ = 0;
  Tick now_ = 0;
};

}  // namespace

Trace detail::import_umockdev(ImportSource& source, const ImportOptions& options) {
  return UmockdevImporter(source, options).run();
}

}  // namespace l6470emu
