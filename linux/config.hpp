// What an emulated board consists of: spidev chains (variants, bus, chip select, gpiochip),
// the clock and the log, parsed from L6470EMU_CHAIN / a config file. No OS calls here.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/variant.hpp"

namespace l6470emu {

/// How the board's virtual clock follows the wall clock.
struct TimeConfig {
  bool virtual_time = false;  ///< true: the host program's own time is the board's (preload: time=virtual)
  double scale = 1.0;         ///< wall mode: virtual seconds per wall second (> 0)
  /// Virtual mode: real time after which, with some thread neither waiting nor entering or
  /// leaving a covered call, virtual time moves on anyway (logged once). 0 = never (idle=off).
  std::int64_t idle_ns = 1'000'000'000;
};

/// One daisy chain behind one spidev chip-select, and the gpiochip carrying its pins.
struct ChainConfig {
  unsigned bus = 0;                        ///< SPI bus number B of /dev/spidevB.C
  unsigned cs = 0;                         ///< chip select C
  std::string path;                        ///< device node, default /dev/spidevB.C
  std::vector<const Variant*> chips;       ///< chip 0 drives MISO
  std::optional<unsigned> gpiochip;        ///< N of /dev/gpiochipN; none = no gpiochip
  std::uint32_t max_speed_hz = 5'000'000;  ///< the device's spi-max-frequency (RD_MAX_SPEED_HZ at open)
  std::uint8_t mode = 0;                   ///< SPI mode the device starts in (as a device tree sets it)
  std::uint32_t bufsiz = 4096;             ///< spidev's bufsiz module parameter
};

/// The whole emulated board.
struct BoardConfig {
  std::vector<ChainConfig> chains;
  TimeConfig time;
  std::string log = "stderr";  ///< where diagnostics go: "stderr", "off" or a file path
  std::string socket;          ///< daemon socket (preload: forward to it instead of emulating in process)
  std::string trace;           ///< record every chain into this native trace file ("" = no recording)
};

/// A config error: one line saying where and what.
struct ConfigError {
  std::string message;
};

/// Parses a board description. Clauses are separated by newlines or ';', words by blanks,
/// '#' starts a comment. A clause with chips= is a chain:
///   bus=0 cs=0 chips=L6470,2xL6480 [path=/dev/spidev0.0] [gpiochip=N|none] [speed=HZ] [mode=0..3] [bufsiz=N]
/// other clauses set globals: time=wall|virtual, scale=F, log=stderr|off|FILE, socket=PATH, trace=FILE.
/// `origin` names the source in error messages ("L6470EMU_CHAIN", a file name).
/// Returns the config, or the first error.
struct ParseResult {
  std::optional<BoardConfig> config;
  ConfigError error;
};
ParseResult parse_board_config(std::string_view text, std::string_view origin);

/// Reads the file and parses it; I/O errors are reported as ConfigErrors.
ParseResult load_board_config_file(const std::string& path);

/// The config text of a board, as parse_board_config reads it (for `serve` to print).
std::string describe_board_config(const BoardConfig& config);

/// The variant called `name` (case-insensitive), or nullptr.
const Variant* lookup_variant(std::string_view name);

/// The variant names lookup_variant knows, comma separated (for error messages).
std::string known_variant_names();

}  // namespace l6470emu
