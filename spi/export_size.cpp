// Export sizes from a trace's events: each format's line lengths as its writer lays them out,
// with saturating sums (a bomb's count must not wrap past the limit it is checked against).
#include "spi/export_size.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "spi/export_vcd.hpp"
#include "spi/trace_native.hpp"

namespace l6470emu {
namespace {

constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();

std::uint64_t saturating_add(std::uint64_t a, std::uint64_t b) { return b > kMax - a ? kMax : a + b; }
std::uint64_t saturating_mul(std::uint64_t a, std::uint64_t b) { return a != 0 && b > kMax / a ? kMax : a * b; }

/// Decimal digits of `n`.
std::uint64_t digits(std::uint64_t n) {
  std::uint64_t d = 1;
  while (n >= 10) {
    n /= 10;
    ++d;
  }
  return d;
}

/// Characters of `n` bytes as hex separated by spaces ("D0 00 7E").
std::uint64_t hex_chars(std::uint64_t n) { return n == 0 ? 0 : 3 * n - 1; }

/// The native line of a frame, newline included (trace_native.cpp's write_frame_body).
std::uint64_t native_frame_line(const TraceEvent& e) {
  char time[kMaxTimeChars];
  std::uint64_t n = static_cast<std::uint64_t>(write_seconds(time, e.tick) - time);
  n += 7 + static_cast<std::uint64_t>(write_microseconds(time, e.duration) - time) + 2;  // " frame " TIME "us"
  if (!e.mosi.empty()) n += 1 + hex_chars(e.mosi.size());
  if (!e.miso.empty()) n += 2 + (e.mosi.empty() ? 0 : 1 + hex_chars(e.miso.size()));
  return n + 1;
}

}  // namespace

ExportSizeCounter::ExportSizeCounter(ExportFormat format, unsigned vcd_timescale_ns)
    : format_(format), unit_ns_(vcd_timescale_ns) {
  if (vcd_timescale_ns != 1 && vcd_timescale_ns != 10 && vcd_timescale_ns != 100)
    throw std::invalid_argument("VCD timescale must be 1, 10 or 100 ns");
}

void ExportSizeCounter::add_bytes(std::uint64_t n) { bytes_ = saturating_add(bytes_, n); }

void ExportSizeCounter::add(const TraceEvent& e) {
  if (e.kind == TraceEventKind::frame) {
    ++frames_;
    frame_bytes_ = saturating_add(frame_bytes_, e.mosi.size());
  }
  switch (format_) {
    case ExportFormat::native:
      if (e.repetition != 0) return;
      [[fallthrough]];
    case ExportFormat::native_expanded:
      add_bytes(e.kind == TraceEventKind::frame ? native_frame_line(e) : NativeTraceWriter::format_event(e).size() + 1);
      return;
    case ExportFormat::umockdev_ioctl:
      if (e.kind != TraceEventKind::frame) {
        add_bytes(2 + NativeTraceWriter::format_event(e).size() + 1);  // "# LINE\n"
      } else if (e.mosi.empty()) {
        add_bytes(std::string_view("# empty CS frame at  s\n").size() + format_seconds(e.tick).size());
      } else {
        const std::uint64_t line = 3 + 2 * static_cast<std::uint64_t>(e.mosi.size()) + 1;  // "TW HEX\n"
        const bool answer = !e.miso.empty() && e.miso_known.empty();                      // " R HEX\n"
        add_bytes(answer ? 2 * line : line);
      }
      return;
    case ExportFormat::vcd:
      if (e.kind == TraceEventKind::frame) add_vcd_frame(e);
      return;
  }
}

void ExportSizeCounter::add_vcd_frame(const TraceEvent& e) {
  // As SpiVcdWaveform::draw lays a frame out: CS falls at t0, no earlier than one unit after
  // the last change; then 2 half periods per bit of at least one unit each, then CS rises.
  std::uint64_t t0 = std::max(ns_from_ticks(e.tick), vcd_last_ns_ + unit_ns_);
  t0 = (t0 + unit_ns_ - 1) / unit_ns_ * unit_ns_;
  const std::uint64_t edges = saturating_mul(16, e.mosi.size());  // SCK falls and rises
  // CS falling, each SCK edge and CS rising at a time of its own: "#UNITS\n" and "0X\n" (a
  // 1-bit wire's one-character id), the times having at least the digits of t0's.
  const std::uint64_t per_change = digits(t0 / unit_ns_) + 2 + 3;
  add_bytes(saturating_mul(saturating_add(edges, 2), per_change));
  vcd_last_ns_ = std::max(saturating_add(t0, saturating_mul(saturating_add(edges, 1), unit_ns_)), ns_from_ticks(e.end()));
}

}  // namespace l6470emu
