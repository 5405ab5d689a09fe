// What an emulated board consists of: spidev chains (variants, bus, chip select, gpiochip, the
// microcontroller pins they are wired to), the clock, the log and a firmware run's timing,
// parsed from L6470EMU_CHAIN / a config file. No OS calls here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "board/check_rules.hpp"
#include "board/pin_map.hpp"
#include "core/axis_spec.hpp"
#include "core/tick.hpp"
#include "core/variant.hpp"
#include "daisychain/chip_numbering.hpp"

namespace l6470emu {

/// How the board's virtual clock follows the wall clock.
struct TimeConfig {
  bool virtual_time = false;  ///< true: the host program's own time is the board's (preload: time=virtual)
  double scale = 1.0;         ///< wall mode: virtual seconds per wall second (> 0)
  /// Virtual mode: real time after which, with some thread neither waiting nor entering or
  /// leaving a covered call, virtual time moves on anyway (logged once). 0 = never (idle=off);
  /// the parser accepts 0.001 s to 3600 s.
  std::int64_t idle_ns = 1'000'000'000;
};

/// One daisy chain behind one spidev chip-select, and the gpiochip carrying its pins.
struct ChainConfig {
  unsigned bus = 0;                        ///< SPI bus number B of /dev/spidevB.C
  unsigned cs = 0;                         ///< chip select C
  std::string path;                        ///< device node, default /dev/spidevB.C
  std::vector<const Variant*> chips;       ///< the chain's order: chips[0] drives MISO, whatever the numbering
  std::optional<unsigned> gpiochip;        ///< N of /dev/gpiochipN; none = no gpiochip
  std::uint32_t max_speed_hz = 5'000'000;  ///< the device's spi-max-frequency (RD_MAX_SPEED_HZ at open)
  std::uint8_t mode = 0;                   ///< SPI mode the device starts in (as a device tree sets it)
  std::uint32_t bufsiz = 4096;             ///< spidev's bufsiz module parameter
  /// axis.K=...: the mechanics behind chip K (core/axis_text.hpp), ascending K.
  std::vector<std::pair<std::size_t, AxisSpec>> axes;
  /// cs_pin=, busy_pin=, ..., spi=: the microcontroller pins of a firmware run (board/pin_map.hpp).
  ChainPins pins;
};

/// How a firmware run (firmware/) spends virtual time and where it ends (docs/firmware.md).
struct FirmwareTiming {
  Tick call_ticks = 4;                          ///< call_time=: what each HAL call costs (1 µs)
  Tick loop_ticks = 40;                         ///< loop_time=: each loop() iteration's own cost (10 µs)
  Tick limit_ticks = 60 * kTicksPerSecond;      ///< limit=: the run ends at this virtual time (60 s)
  std::uint32_t apb_clock_hz = 84'000'000;      ///< apb_clock=: the clock an STM32 SPI prescaler divides
  bool operator==(const FirmwareTiming&) const = default;
};

/// The whole emulated board.
struct BoardConfig {
  std::vector<ChainConfig> chains;
  TimeConfig time;
  std::string log = "stderr";  ///< where diagnostics go: "stderr", "off" or a file path
  std::string socket;          ///< daemon socket (preload: forward to it instead of emulating in process)
  std::string trace;           ///< record every chain into this native trace file ("" = no recording)
  /// Merge interface coverage into this file when the board's run ends ("" = none; serve
  /// --coverage, run --coverage: not a key of the description).
  std::string coverage;
  NumberFrom numbering = NumberFrom::miso;  ///< how diagnostics and `ctl` number the chips (numbering=)
  CheckConfig check;                        ///< the driver sanitizer: check= and check.allow=
  bool check_given = false;                 ///< the description said check= (a front's own default yields to it)
  FirmwareTiming firmware;                  ///< call_time=, loop_time=, limit=, apb_clock= (firmware runs)
};

/// A config error: one line saying where and what.
struct ConfigError {
  std::string message;
};

/// Parses a board description. Lines end at newlines, '#' starts a comment that runs to the end
/// of the line, ';' separates clauses within a line, words are separated by blanks. Each word is
/// key=value, each key at most once per clause. A clause with chips= is a chain:
///   chips=L6470,2xL6480 [bus=0..32767] [cs=0..255] [path=/dev/NAME] [gpiochip=0..1023|none]
///   [speed=HZ] [mode=0..3] [bufsiz=N] [axis.K=ITEM,... (a motor, load, stops and switches behind chip K)]
///   [cs_pin=PIN] [busy_pin=|flag_pin=|sw_pin=|stck_pin=|stby_rst_pin=|dir_pin=PIN or PIN,PIN,... one per chip]
///   [spi=SPI|SPI1..SPI9|HSPI|VSPI|FSPI|hspiN] (the microcontroller side of a firmware run)
/// Board-wide keys may stand in any clause, a chain's or one of their own, each at most once in
/// the whole description: time=wall|virtual, scale=F (wall time), idle=SECONDS|off (virtual
/// time), log=stderr|off|FILE, socket=PATH, trace=FILE, numbering=miso|mosi (which end chip 0
/// is at in diagnostics and `ctl`; chips= always lists the MISO end first), check=off|warn|error
/// and check.allow=RULE,... (the driver sanitizer, board/check_rules.hpp), and for firmware runs
/// call_time=, loop_time=, limit= (durations: 250ns, 1us, 10ms, 60s) and apb_clock=HZ. Every value is checked against its
/// range; docs/linux.md has the table. `origin` names the source in error messages
/// ("L6470EMU_CHAIN", a file name). Returns the config, or the first error, on one line:
/// "l6470emu: config ORIGIN, clause N: what", user text quoted by quoted_text.
struct ParseResult {
  std::optional<BoardConfig> config;
  ConfigError error;
};
ParseResult parse_board_config(std::string_view text, std::string_view origin);

/// The longest board description read or parsed (bytes); a longer one is an error. Files are
/// read by linux/board_config_file.hpp.
inline constexpr std::size_t kMaxConfigBytes = std::size_t{1} << 20;

/// How many characters of a user's text an error message shows.
inline constexpr std::size_t kQuotedTextChars = 60;

/// User text made safe for a one-line message: control characters, backslash and non-ASCII
/// bytes written as \xNN, cut to at most `max_chars` characters plus "…" when longer.
std::string shown_text(std::string_view text, std::size_t max_chars = kQuotedTextChars);

/// shown_text in single quotes, followed by " (N bytes)" when cut.
std::string quoted_text(std::string_view text);

/// A chain's chips as chips= writes them, runs of one variant counted: "3xL6470,L6480".
std::string chip_list_text(const std::vector<const Variant*>& chips);

/// The config text of a board, as parse_board_config reads it back (for `serve` to print):
/// scale= in wall time, idle= in virtual time when not the default 1 s, log/socket/trace when set,
/// check= when not warn, check.allow= when it allows any rule.
std::string describe_board_config(const BoardConfig& config);

/// The variant called `name` (case-insensitive), or nullptr.
const Variant* lookup_variant(std::string_view name);

/// The variant names lookup_variant knows, comma separated (for error messages).
std::string known_variant_names();

}  // namespace l6470emu
