// Importers of captures users already have: Saleae Logic 2 SPI analyzer CSV, umockdev
// SPI .ioctl recordings, Linux ftrace spi_* events and sigrok-cli's JSON trace of its spi
// decoder; and recognising which one a file is. They read bytes and times, not meanings.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

#include "spi/trace.hpp"

namespace l6470emu {

/// The trace file formats l6470emu reads.
enum class TraceFormat : std::uint8_t {
  unknown,
  native,      ///< docs/trace-format.md
  saleae,      ///< Logic 2 analyzer table export: name,type,start_time[,duration],"mosi","miso"
  umockdev,    ///< umockdev-record --ioctl of a spidev: @DEV, T/C transfers, W/R bytes
  ftrace,      ///< /sys/kernel/tracing/trace or trace-cmd report with spi:spi_transfer_* events
  sigrok,      ///< sigrok-cli -P spi ... --protocol-decoder-jsontrace
  vcd,         ///< a logic capture as VCD: needs sigrok-cli to decode (tools/ runs it)
};

/// Name as used on the command line ("saleae", ...).
std::string_view to_string(TraceFormat f);
/// The format called `name`, or unknown.
TraceFormat trace_format_named(std::string_view name);

/// Recognises a format from the start of a file (and its name as a hint for VCD).
TraceFormat detect_trace_format(std::string_view head, std::string_view file_name = {});

/// How ftrace transfers are grouped into CS frames.
enum class FtraceFraming : std::uint8_t {
  automatic,  ///< spi_set_cs activate/deactivate when present, else one frame per transfer
  cs,         ///< spi_set_cs events only
  transfer,   ///< every transfer is a CS frame (drivers that set cs_change on every transfer)
  message,    ///< every spi_message is a CS frame (no cs_change inside messages)
};

/// Choices for the importers.
struct ImportOptions {
  /// Which stream when the file holds several: the Saleae analyzer name ("SPI"), the
  /// ftrace device ("spi0.0") or the sigrok decoder instance ("spi-1"). Empty = the only one.
  std::string select;
  FtraceFraming ftrace_framing = FtraceFraming::automatic;
  /// umockdev recordings carry no times: frames are spaced as at this SCK, 1 µs CS high.
  std::uint32_t umockdev_speed_hz = 5'000'000;
  /// The most frames the trace may hold (0: no limit): a capture with more is refused at the
  /// frame that passes the limit (an imported trace is held in memory: about 70 bytes a frame
  /// plus 3 a byte). Native traces: the same bound on the frames `repeat` lines stand for.
  std::uint64_t max_frames = kDefaultMaxTraceFrames;
  /// Told how far reading a file has come (import_trace_file), a few times a second at most
  /// (empty: nobody asks).
  std::function<void(const ReadProgress&)> progress;
};

/// Saleae Logic 2 SPI analyzer CSV export (also the older header without duration,
/// and Logic 1.x "Time [s],Packet ID,MOSI,MISO"). Values in hex, decimal or binary.
Trace import_saleae_csv(std::string_view text, const std::string& name, const ImportOptions& options = {});

/// umockdev SPI .ioctl recording. Times are made up (see ImportOptions::umockdev_speed_hz).
Trace import_umockdev_ioctl(std::string_view text, const std::string& name, const ImportOptions& options = {});

/// Linux ftrace text with spi:spi_transfer_start/stop (and spi_set_cs, spi_message_*) events.
Trace import_ftrace(std::string_view text, const std::string& name, const ImportOptions& options = {});

/// sigrok-cli's JSON trace of the spi decoder (MOSI/MISO transfer or data annotations).
Trace import_sigrok_json(std::string_view text, const std::string& name, const ImportOptions& options = {});

/// Any text format above (or native), by `format`; TraceError for unknown/vcd.
Trace import_trace(std::string_view text, const std::string& name, TraceFormat format,
                   const ImportOptions& options = {});

/// The file at `path` (plain or gzip-compressed) in `format`, read a piece at a time: memory
/// holds the trace, never the file's text (a line is at most kMaxTraceLineBytes, a frame at most
/// kMaxTraceFrameBytes, the trace at most options.max_frames frames). TraceError for unknown/vcd,
/// a file that cannot be read and malformed input, naming the file and line.
Trace import_trace_file(const std::string& path, TraceFormat format, const ImportOptions& options = {});

}  // namespace l6470emu
