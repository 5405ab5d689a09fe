// umockdev .ioctl export: the format umockdev-spi.vala reads ("TW hex", " R hex", '#' comments).
#include "spi/export_umockdev.hpp"

#include <ios>
#include <ostream>
#include <string>

#include "spi/trace_native.hpp"

namespace l6470emu {
namespace {

void put_hex(std::string& s, std::span<const std::uint8_t> bytes) {
  static constexpr char kHex[] = "0123456789abcdef";
  for (std::uint8_t b : bytes) {
    s += kHex[b >> 4];
    s += kHex[b & 15];
  }
}

}  // namespace

UmockdevExportStats export_umockdev_ioctl(TraceReader& in, std::ostream& out, std::string_view device) {
  UmockdevExportStats stats;
  const TraceHeader& h = in.header();
  std::string line = "@DEV " + std::string(device) + " (SPI)\n";
  line += "# written by l6470emu";
  if (!h.name.empty()) line += " from " + h.name;
  line += "; times are not part of the umockdev format\n";
  if (!h.chain.empty()) line += "# chain " + h.chain + "\n";
  out << line;
  TraceEvent e;
  while (in.next(e)) {
    line.clear();
    if (e.kind != TraceEventKind::frame) {
      line = "# " + NativeTraceWriter::format_event(e) + "\n";
    } else if (e.mosi.empty()) {
      ++stats.empty_frames;
      line = "# empty CS frame at " + format_seconds(e.tick) + " s\n";
    } else {
      ++stats.frames;
      line = "TW ";
      put_hex(line, e.mosi);
      line += '\n';
      if (!e.miso.empty() && e.miso_known.empty()) {
        line += " R ";
        put_hex(line, e.miso);
        line += '\n';
      } else {
        ++stats.frames_without_miso;
      }
    }
    out << line;
    if (!out) throw std::ios_base::failure("umockdev output: write failed");
  }
  return stats;
}

}  // namespace l6470emu
