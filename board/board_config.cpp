// Parser of the board description (L6470EMU_CHAIN, config files, `serve --chain`): every key
// checked against its range, one error line that says where, what and how to write it instead.
#include "board/board_config.hpp"

#include "core/axis_text.hpp"
#include "core/near_miss.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <utility>

namespace l6470emu {
namespace {

constexpr std::size_t kMaxChipsPerChain = 256;
constexpr std::size_t kMaxChains = 256;
constexpr std::size_t kMaxPathBytes = 255;
constexpr std::size_t kMaxSocketPathBytes = 107;  // sizeof sockaddr_un::sun_path - 1
constexpr unsigned kMaxGpiochip = 1023;

enum class Scope { chain, board };

struct KeySpec {
  std::string_view name;
  Scope scope;
  std::string_view example;  // a whole word, as a user would write it
};

// Every key, in the order the docs table lists them.
constexpr std::array<KeySpec, 32> kKeys{{
    {"chips", Scope::chain, "chips=2xL6470,L6480"},
    {"bus", Scope::chain, "bus=0"},
    {"cs", Scope::chain, "cs=1"},
    {"path", Scope::chain, "path=/dev/spidev-motors"},
    {"gpiochip", Scope::chain, "gpiochip=4"},
    {"speed", Scope::chain, "speed=2000000"},
    {"mode", Scope::chain, "mode=3"},
    {"bufsiz", Scope::chain, "bufsiz=65536"},
    {"cs_pin", Scope::chain, "cs_pin=D10"},
    {"busy_pin", Scope::chain, "busy_pin=D3"},
    {"flag_pin", Scope::chain, "flag_pin=D2"},
    {"sw_pin", Scope::chain, "sw_pin=D5"},
    {"stck_pin", Scope::chain, "stck_pin=D7"},
    {"stby_rst_pin", Scope::chain, "stby_rst_pin=D6"},
    {"dir_pin", Scope::chain, "dir_pin=D4"},
    {"spi", Scope::chain, "spi=SPI1"},
    {"sck_pin", Scope::chain, "sck_pin=D13"},
    {"mosi_pin", Scope::chain, "mosi_pin=D11"},
    {"miso_pin", Scope::chain, "miso_pin=D12"},
    {"time", Scope::board, "time=virtual"},
    {"scale", Scope::board, "scale=10"},
    {"idle", Scope::board, "idle=0.2"},
    {"log", Scope::board, "log=/tmp/l6470emu.log"},
    {"socket", Scope::board, "socket=/tmp/l6470emu.sock"},
    {"trace", Scope::board, "trace=run.trace"},
    {"numbering", Scope::board, "numbering=mosi"},
    {"check", Scope::board, "check=error"},
    {"check.allow", Scope::board, "check.allow=SPI_MODE,FRAME_LENGTH"},
    {"call_time", Scope::board, "call_time=1us"},
    {"loop_time", Scope::board, "loop_time=10us"},
    {"limit", Scope::board, "limit=120s"},
    {"apb_clock", Scope::board, "apb_clock=84000000"},
}};

const KeySpec* find_key(std::string_view name) {
  for (const KeySpec& k : kKeys)
    if (k.name == name) return &k;
  return nullptr;
}

std::string key_list(Scope scope) {
  std::string out;
  for (const KeySpec& k : kKeys) {
    if (k.scope != scope) continue;
    // The chip pins' keys, shortened: busy/flag/sw/stck/stby_rst/dir_pin.
    if (k.name.size() > 4 && k.name.substr(k.name.size() - 4) == "_pin") {
      if (k.name == "cs_pin") out += ", cs/sck/mosi/miso_pin";
      if (k.name == "busy_pin") out += ", busy/flag/sw/stck/stby_rst/dir_pin";
      continue;
    }
    out += (out.empty() ? "" : ", ") + std::string(k.name);
  }
  return out;
}

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split_words(std::string_view s) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && is_blank(s[i])) ++i;
    std::size_t j = i;
    while (j < s.size() && !is_blank(s[j])) ++j;
    if (j > i) words.push_back(s.substr(i, j - i));
    i = j;
  }
  return words;
}

bool is_control(unsigned char c) { return c < 0x20 || c == 0x7f; }

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// Words users write for a key under another name.
std::string_view key_alias(std::string_view key) {
  static constexpr std::pair<std::string_view, std::string_view> kAliases[] = {
      {"chip", "chips"},       {"variant", "chips"},  {"variants", "chips"},   {"device", "path"},
      {"dev", "path"},         {"node", "path"},      {"hz", "speed"},         {"speed_hz", "speed"},
      {"max_speed_hz", "speed"}, {"timescale", "scale"}, {"time-scale", "scale"}, {"time_scale", "scale"},
      {"gpio", "gpiochip"},    {"record", "trace"},   {"chipselect", "cs"},    {"ss_pin", "cs_pin"},
      {"ss", "cs_pin"},        {"nss", "cs_pin"},     {"busy", "busy_pin"},    {"flag", "flag_pin"},
      {"sw", "sw_pin"},        {"stck", "stck_pin"},  {"stby", "stby_rst_pin"}, {"stby_pin", "stby_rst_pin"},
      {"dir", "dir_pin"},      {"direction_pin", "dir_pin"},
      {"reset_pin", "stby_rst_pin"}, {"rst_pin", "stby_rst_pin"}, {"stbyrst_pin", "stby_rst_pin"},
      {"spi_bus", "spi"},      {"controller", "spi"}, {"call_cost", "call_time"}, {"loop_cost", "loop_time"},
      {"time_limit", "limit"}, {"run_limit", "limit"}, {"apb", "apb_clock"},  {"pclk", "apb_clock"},
      {"sanitize", "check"},   {"sanitizer", "check"}, {"allow", "check.allow"}, {"check_allow", "check.allow"},
      {"check-allow", "check.allow"}, {"clk_pin", "sck_pin"}, {"sclk_pin", "sck_pin"}, {"clock_pin", "sck_pin"},
      {"sck", "sck_pin"},      {"mosi", "mosi_pin"},  {"sdi_pin", "mosi_pin"}, {"copi_pin", "mosi_pin"},
      {"dout_pin", "mosi_pin"}, {"miso", "miso_pin"}, {"sdo_pin", "miso_pin"}, {"cipo_pin", "miso_pin"},
      {"din_pin", "miso_pin"},
  };
  const std::string k = lower(key);
  for (const auto& [alias, real] : kAliases)
    if (k == alias) return real;
  return {};
}

std::string key_suggestion(std::string_view key) {
  if (const std::string_view alias = key_alias(key); !alias.empty()) return std::string(alias);
  std::vector<std::string> names;
  for (const KeySpec& k : kKeys) names.emplace_back(k.name);
  return closest_names(key, names);
}

template <typename T>
bool parse_uint(std::string_view s, T& out, unsigned long long min, unsigned long long max) {
  unsigned long long v = 0;
  const auto* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, v, 10);
  if (ec != std::errc{} || p != end || s.empty() || v < min || v > max) return false;
  out = static_cast<T>(v);
  return true;
}

// A plain decimal number ("10", "0.5", "2e3"): no sign, no inf/nan, no hex, within [min, max].
bool parse_decimal(std::string_view s, double& out, double min, double max) {
  if (s.empty() || !(std::isdigit(static_cast<unsigned char>(s[0])) || s[0] == '.')) return false;
  for (char c : s)
    if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == 'e' || c == 'E' || c == '+' || c == '-'))
      return false;
  double v = 0;
  const auto* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, v, std::chars_format::general);
  if (ec != std::errc{} || p != end || !std::isfinite(v) || v < min || v > max) return false;
  out = v;
  return true;
}

// Device nodes of every Linux system that a chain must not take over in the host program.
std::string system_node_reason(std::string_view name) {
  const std::string_view first = name.substr(0, name.find('/'));
  static constexpr std::string_view kStandard[] = {"null",  "zero",  "full",   "random", "urandom", "console",
                                                    "ptmx",  "kmsg",  "mem",    "kmem",   "port",    "stdin",
                                                    "stdout", "stderr", "log",  "initctl", "fuse",   "net",
                                                    "pts",   "fd",    "shm",    "mqueue", "hugepages", "tty"};
  for (std::string_view s : kStandard)
    if (first == s) return "a standard device of the system";
  if (first.substr(0, 3) == "tty") return "a terminal";
  if (first.substr(0, 8) == "gpiochip") return "where the emulator puts a chain's pins (gpiochip=N)";
  return "";
}

// The shortest text that reads back as exactly `v`.
std::string shortest(double v) {
  std::array<char, 32> buf{};
  const auto [p, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return ec == std::errc{} ? std::string(buf.data(), p) : std::to_string(v);
}

// A duration with its unit ("250ns", "1us", "1.5ms", "60s") as whole 250 ns ticks, from
// `min` to `max` ticks; "" or what is wrong.
std::string parse_duration(std::string_view s, Tick& out, Tick min, Tick max) {
  static constexpr std::pair<std::string_view, long double> kUnits[] = {
      {"ns", 1.0L}, {"us", 1e3L}, {"ms", 1e6L}, {"s", 1e9L}};
  for (const auto& [unit, ns] : kUnits) {
    if (s.size() <= unit.size() || s.substr(s.size() - unit.size()) != unit) continue;
    const std::string_view digits = s.substr(0, s.size() - unit.size());
    if (!digits.empty() && (digits.back() == 'n' || digits.back() == 'u' || digits.back() == 'm')) continue;  // "10ms" is not "10m" + "s"
    double v = 0;
    if (!parse_decimal(digits, v, 0, 1e15)) return "a number with a unit (ns, us, ms or s)";
    const long double ticks = static_cast<long double>(v) * ns / 250.0L;
    const long double whole = std::round(ticks);
    if (std::fabs(ticks - whole) > 1e-6L * std::max(1.0L, whole)) return "a whole number of 250 ns ticks (the chip's tick)";
    if (whole < static_cast<long double>(min) || whole > static_cast<long double>(max)) return "out of range";
    out = static_cast<Tick>(whole);
    return "";
  }
  return "a number with a unit (ns, us, ms or s)";
}

// `ticks` as parse_duration reads it back, in the largest unit that keeps it whole.
std::string duration_text(Tick ticks) {
  const std::uint64_t ns = ticks * 250;
  if (ns % 1'000'000'000 == 0) return std::to_string(ns / 1'000'000'000) + "s";
  if (ns % 1'000'000 == 0) return std::to_string(ns / 1'000'000) + "ms";
  if (ns % 1'000 == 0) return std::to_string(ns / 1'000) + "us";
  return std::to_string(ns) + "ns";
}

// The shortest way to write a pin list (one pin for all chips, or one per chip with '-' for none).
std::string pin_list_text(const ChipPinList& list) {
  std::string out;
  for (std::size_t i = 0; i < list.size(); ++i) out += (i ? "," : "") + (list[i] ? to_string(*list[i]) : std::string("-"));
  return out;
}

// How the config file is read: at most this much (a board description is a few lines).
constexpr std::size_t kMaxBytes = kMaxConfigBytes;

struct Setting {
  unsigned clause = 0;
  std::string value;
};

struct Parser {
  std::string_view origin;
  std::string error;
  unsigned clause_no = 0;
  unsigned line_no = 0;     // line of the clause being parsed (1-based)
  bool show_line = false;   // the text has several lines: errors name the line too
  std::map<std::string, Setting, std::less<>> board_keys;  // board-wide key -> where it was set
  std::vector<unsigned> chain_clause;                      // clause of each chain
  std::vector<unsigned> chain_line;                        // line of each chain
  std::vector<bool> chain_gpiochip_given;                  // gpiochip= written for each chain

  bool fail(const std::string& what) {
    if (error.empty()) {
      std::ostringstream o;
      o << "l6470emu: config " << shown_text(origin, 200);
      if (show_line) o << ":" << line_no;
      o << ", clause " << clause_no << ": " << what;
      error = o.str();
    }
    return false;
  }

  // "L6470", "3xL6470", "L6470x3", "3*L6470", "L6470*3"
  bool parse_chip_list(std::string_view list, std::vector<const Variant*>& chips) {
    std::vector<std::pair<const Variant*, unsigned long long>> items;
    std::size_t start = 0;
    while (start <= list.size()) {
      std::size_t comma = list.find(',', start);
      if (comma == std::string_view::npos) comma = list.size();
      const std::string_view item = list.substr(start, comma - start);
      start = comma + 1;
      if (item.empty()) return fail("empty entry in chips=" + quoted_text(list) + " (write e.g. chips=L6470,2xL6480)");
      std::string_view name = item, count_text;
      if (!lookup_variant(item)) {
        std::size_t d = 0;
        while (d < item.size() && std::isdigit(static_cast<unsigned char>(item[d]))) ++d;
        std::size_t t = item.size();
        while (t > 0 && std::isdigit(static_cast<unsigned char>(item[t - 1]))) --t;
        auto is_sep = [](char c) { return c == 'x' || c == 'X' || c == '*'; };
        if (d > 0 && d < item.size() && is_sep(item[d])) {
          count_text = item.substr(0, d);
          name = item.substr(d + 1);
        } else if (t < item.size() && t > 0 && is_sep(item[t - 1])) {
          count_text = item.substr(t);
          name = item.substr(0, t - 1);
        }
      }
      if (name.empty())
        return fail(quoted_text(item) + " names no chip variant (write e.g. chips=3xL6470; known: " + known_variant_names() +
                    ")");
      const Variant* v = lookup_variant(name);
      if (v == nullptr)
        return fail("unknown chip variant " + quoted_text(name) + " (" + variant_suggestion(name) +
                    "known: " + known_variant_names() + ")");
      unsigned long long count = 1;
      if (!count_text.empty()) {
        const bool fits = parse_uint(count_text, count, 0, ~0ull);
        if (count == 0 && fits) return fail("chip count 0 in " + quoted_text(item) + ": a chain holds 1 to 256 chips");
        if (!fits || count > kMaxChipsPerChain)
          return fail("a chain holds at most 256 chips; " + quoted_text(item) + " asks for " + shown_text(count_text));
      }
      items.emplace_back(v, count);
    }
    unsigned long long total = 0;
    for (const auto& [v, n] : items) total += n;
    if (total > kMaxChipsPerChain)
      return fail("a chain holds at most 256 chips; chips=" + quoted_text(list) + " asks for " + std::to_string(total));
    for (const auto& [v, n] : items) chips.insert(chips.end(), n, v);
    return true;
  }

  bool check_path(std::string_view value) {
    const std::string q = quoted_text(value);
    if (value.size() > kMaxPathBytes)
      return fail("path is " + std::to_string(value.size()) + " bytes long; a device node name has at most 255");
    if (value.substr(0, 5) != "/dev/")
      return fail("path must be a device node under /dev/ (e.g. path=/dev/spidev0.0), not " + q);
    const std::string_view name = value.substr(5);
    if (name.empty() || name.back() == '/') return fail("path " + q + " names a directory, not a device node");
    for (char c : name)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-' || c == '+' || c == ':' ||
            c == '@' || c == '/'))
        return fail("path " + q + " has a character a device node name does not use (letters, digits and . _ - + : @ /)");
    std::size_t start = 0;
    while (start <= name.size()) {
      std::size_t slash = name.find('/', start);
      if (slash == std::string_view::npos) slash = name.size();
      const std::string_view part = name.substr(start, slash - start);
      if (part.empty() || part == "." || part == "..")
        return fail("path " + q + " must name a node directly (no empty, '.' or '..' parts)");
      start = slash + 1;
    }
    if (const std::string why = system_node_reason(name); !why.empty())
      return fail("path " + q + " is " + why + ", not a spidev node: the emulator would take it over in the host program "
                  "(write e.g. path=/dev/spidev0.0, or leave path= out)");
    return true;
  }

  // A board-wide key: given at most once in the whole description.
  bool set_board_key(const KeySpec& key, std::string_view value, BoardConfig& cfg) {
    const std::string k(key.name);
    if (auto it = board_keys.find(k); it != board_keys.end())
      return fail(k + "= is given twice: clause " + std::to_string(it->second.clause) + " says " +
                  quoted_text(it->second.value) + ", clause " + std::to_string(clause_no) + " says " + quoted_text(value) +
                  " (a board-wide key is given once)");
    board_keys[k] = {clause_no, std::string(value)};
    const std::string q = quoted_text(value);
    if (k == "time") {
      if (value == "wall")
        cfg.time.virtual_time = false;
      else if (value == "virtual")
        cfg.time.virtual_time = true;
      else
        return fail("time must be wall or virtual, not " + q);
    } else if (k == "scale") {
      if (!parse_decimal(value, cfg.time.scale, 1e-6, 1e6))
        return fail("scale must be a number from 0.000001 to 1000000 (virtual seconds per wall second), not " + q);
    } else if (k == "idle") {
      double s = 0;
      if (value == "off")
        cfg.time.idle_ns = 0;
      else if (parse_decimal(value, s, 0.001, 3600))
        cfg.time.idle_ns = std::llround(s * 1e9);
      else
        return fail("idle must be off or a number of seconds from 0.001 to 3600, not " + q);
    } else if (k == "log") {
      if (value == "stdout" || value == "none" || value == "null")
        return fail("log=" + std::string(value) + " would be a file of that name: write log=stderr, log=off, or log=./" +
                    std::string(value) + " if a file is meant");
      if (value.back() == '/') return fail("log " + q + " names a directory; give a file");
      cfg.log = std::string(value);
    } else if (k == "socket") {
      if (value.size() > kMaxSocketPathBytes)
        return fail("socket path is " + std::to_string(value.size()) + " bytes long; a Unix socket path has at most 107");
      if (value.back() == '/') return fail("socket " + q + " names a directory; give the socket's path");
      cfg.socket = std::string(value);
    } else if (k == "trace") {
      if (value.back() == '/') return fail("trace " + q + " names a directory; give a file");
      cfg.trace = std::string(value);
    } else if (k == "check") {
      std::string why;
      const auto level = parse_check_level(value, why);
      if (!level) return fail("check " + why);
      cfg.check.level = *level;
      cfg.check_given = true;
    } else if (k == "check.allow") {
      std::string why;
      const auto rules = parse_rule_list(value, why);
      if (!rules) return fail("check.allow " + why);
      cfg.check.allowed = *rules;
    } else if (k == "numbering") {
      const auto from = number_from_named(value);
      if (!from)
        return fail("numbering must be miso (chip 0 drives MISO) or mosi (chip 0 reads the host's MOSI), not " + q);
      cfg.numbering = *from;
    } else if (k == "call_time" || k == "loop_time" || k == "limit") {
      const bool limit = k == "limit";
      Tick& ticks = limit ? cfg.firmware.limit_ticks : k == "call_time" ? cfg.firmware.call_ticks : cfg.firmware.loop_ticks;
      const std::string range = limit ? "from 1ms to 1000000s" : "from 250ns to 1s";
      const std::string example = " (e.g. " + std::string(key.example) + ")";
      const std::string why = limit ? parse_duration(value, ticks, ticks_from_ms(1), Tick{1'000'000} * kTicksPerSecond)
                                    : parse_duration(value, ticks, 1, kTicksPerSecond);
      if (!why.empty())
        return fail(k + " must be " + (why == "out of range" ? range : why + ", " + range) + example + ", not " + q);
    } else if (k == "apb_clock") {
      if (!parse_uint(value, cfg.firmware.apb_clock_hz, 1000, 1'000'000'000))
        return fail("apb_clock must be a frequency in Hz from 1000 to 1000000000 (e.g. apb_clock=84000000), not " + q);
    }
    if ((k == "log" || k == "trace") && !cfg.trace.empty() && cfg.trace == cfg.log)
      return fail("log= and trace= name the same file " + q + ": diagnostics would be mixed into the trace");
    // Combinations that would be silently ignored.
    auto time_given = board_keys.find(std::string_view("time"));
    if (time_given != board_keys.end()) {
      const bool virtual_time = time_given->second.value == "virtual";
      if (virtual_time && board_keys.count(std::string_view("scale")))
        return fail("scale= applies to time=wall only: with time=virtual (clause " + std::to_string(time_given->second.clause) +
                    ") the host program's own clock is the board's");
      if (!virtual_time && board_keys.count(std::string_view("idle")))
        return fail("idle= applies to time=virtual only, and clause " + std::to_string(time_given->second.clause) +
                    " says time=wall");
    }
    return true;
  }

  bool set_chain_key(const KeySpec& key, std::string_view value, ChainConfig& chain) {
    const std::string q = quoted_text(value);
    const std::string_view k = key.name;
    if (k == "bus") {
      if (!parse_uint(value, chain.bus, 0, 32767)) return fail("bus must be a number from 0 to 32767, not " + q);
    } else if (k == "cs") {
      if (!parse_uint(value, chain.cs, 0, 255)) return fail("cs must be a number from 0 to 255, not " + q);
    } else if (k == "path") {
      if (!check_path(value)) return false;
      chain.path = std::string(value);
    } else if (k == "chips") {
      if (!parse_chip_list(value, chain.chips)) return false;
    } else if (k == "gpiochip") {
      unsigned n = 0;
      if (value == "none")
        chain.gpiochip.reset();
      else if (parse_uint(value, n, 0, kMaxGpiochip))
        chain.gpiochip = n;
      else
        return fail("gpiochip must be a number from 0 to 1023 or none, not " + q);
    } else if (k == "speed") {
      if (!parse_uint(value, chain.max_speed_hz, 1, 1'000'000'000))
        return fail("speed must be a frequency in Hz from 1 to 1000000000 (e.g. speed=5000000), not " + q);
    } else if (k == "mode") {
      if (!parse_uint(value, chain.mode, 0, 3)) return fail("mode must be an SPI mode from 0 to 3, not " + q);
    } else if (k == "bufsiz") {
      if (!parse_uint(value, chain.bufsiz, 1, 1u << 22)) return fail("bufsiz must be a number from 1 to 4194304, not " + q);
    } else if (k == "cs_pin" || k == "sck_pin" || k == "mosi_pin" || k == "miso_pin") {
      const auto pin = parse_mcu_pin(value);
      if (!pin) return fail(pin_error(k, value));
      (k == "cs_pin" ? chain.pins.cs : k == "sck_pin" ? chain.pins.sck : k == "mosi_pin" ? chain.pins.mosi : chain.pins.miso) = *pin;
    } else if (k == "spi") {
      const auto name = parse_spi_controller(value);
      if (!name)
        return fail("spi must name an SPI controller: SPI, SPI1 to SPI9, HSPI, VSPI, FSPI, or hspi1 to hspi9 (an STM32 "
                    "HAL handle), not " + q);
      chain.pins.spi = *name;
    } else {
      for (unsigned p = 0; p < kPinsPerChip; ++p) {
        if (k != pin_key(static_cast<Pin>(p))) continue;
        ChipPinList list;
        std::size_t start = 0;
        while (start <= value.size()) {
          std::size_t comma = value.find(',', start);
          if (comma == std::string_view::npos) comma = value.size();
          const std::string_view item = value.substr(start, comma - start);
          start = comma + 1;
          if (item == "-") {
            list.emplace_back();
            continue;
          }
          const auto pin = parse_mcu_pin(item);
          if (!pin) return fail(pin_error(k, item) + (value.find(',') == std::string_view::npos ? "" : " in " + q));
          list.emplace_back(*pin);
          if (list.size() > kMaxChipsPerChain) return fail(std::string(k) + "= lists more pins than a chain has chips");
        }
        chain.pins.chip[p] = std::move(list);
      }
    }
    return true;
  }

  static std::string pin_error(std::string_view key, std::string_view value) {
    return std::string(key) + " must be a microcontroller pin: an Arduino pin (10, D10, A0 to A7, GPIO5; 0 to 127) or an " +
           "STM32 port pin (PA0 to PK15), " + (pin_key_is_chip(key) ? "'-' for none, " : "") +
           "not " + quoted_text(value);
  }

  static bool pin_key_is_chip(std::string_view key) {
    for (unsigned p = 0; p < kPinsPerChip; ++p)
      if (key == pin_key(static_cast<Pin>(p))) return true;
    return false;
  }

  // The pin lists of a chain just read: one pin for every chip, or one per chip. SPI at the
  // pins: sck_pin= and mosi_pin= together, with a cs_pin= to select the chain.
  bool check_pin_lists(const ChainConfig& chain) {
    if (chain.pins.sck.has_value() != chain.pins.mosi.has_value())
      return fail(std::string(chain.pins.sck ? "sck_pin= needs mosi_pin=" : "mosi_pin= needs sck_pin=") +
                  ": SPI at the pins needs its clock and its data pin (miso_pin= too, to read the chips)");
    if (chain.pins.miso && !chain.pins.sck) return fail("miso_pin= needs sck_pin= and mosi_pin=: SPI at the pins needs its clock and its data pin");
    if (chain.pins.sck && !chain.pins.cs) return fail("sck_pin= needs cs_pin=: nothing else selects a chain whose SPI is on pins");
    for (unsigned p = 0; p < kPinsPerChip; ++p) {
      const ChipPinList& list = chain.pins.chip[p];
      if (list.size() <= 1 || list.size() == chain.chips.size()) continue;
      const std::string k = pin_key(static_cast<Pin>(p));
      return fail(k + "= lists " + std::to_string(list.size()) + " pins for a chain of " + std::to_string(chain.chips.size()) +
                  " chip" + (chain.chips.size() == 1 ? "" : "s") +
                  ": give one pin for all of them or one per chip, '-' for none (e.g. " + k + "=D3,D4,-)");
    }
    return true;
  }

  // No microcontroller pin drives two chip selects, a chip select and a chip pin, or a chip
  // output (BUSY, FLAG: open drain, wired together) and a chip input (SW, STCK, STBY_RST).
  bool check_pin_uses(const BoardConfig& cfg, const ChainConfig& chain) {
    struct Use {
      McuPin pin;
      std::string key;
      int kind;                 // 0 chip select, 1 chip output, 2 chip input, 3 an SPI pin
      std::size_t chain;        // index; cfg.chains.size() = this chain
    };
    std::vector<Use> uses;
    auto add = [&](const ChainConfig& c, std::size_t index) {
      if (c.pins.cs) uses.push_back({*c.pins.cs, "cs_pin", 0, index});
      if (c.pins.sck) uses.push_back({*c.pins.sck, "sck_pin", 3, index});
      if (c.pins.mosi) uses.push_back({*c.pins.mosi, "mosi_pin", 3, index});
      if (c.pins.miso) uses.push_back({*c.pins.miso, "miso_pin", 3, index});
      for (unsigned p = 0; p < kPinsPerChip; ++p)
        for (const auto& pin : c.pins.chip[p])
          if (pin) uses.push_back({*pin, pin_key(static_cast<Pin>(p)), pin_is_chip_output(static_cast<Pin>(p)) ? 1 : 2, index});
    };
    for (std::size_t i = 0; i < cfg.chains.size(); ++i) add(cfg.chains[i], i);
    const std::size_t first_new = uses.size();
    add(chain, cfg.chains.size());
    for (std::size_t b = first_new; b < uses.size(); ++b) {
      for (std::size_t a = 0; a < b; ++a) {
        const Use &x = uses[a], &y = uses[b];
        if (x.pin != y.pin) continue;
        const bool same_chain = x.chain == y.chain;
        if (x.kind == y.kind && x.kind != 0 && x.kind != 3) continue;  // outputs wired together, or one line driving several inputs
        if (x.kind == 3 && y.kind == 3 && x.key == y.key && !same_chain) continue;  // chains sharing a pin-level bus
        if (same_chain && x.key == y.key && x.kind != 0) continue;
        const std::string where = same_chain ? "of this chain" : "of the chain in clause " + std::to_string(chain_clause[x.chain]);
        const std::string why = x.kind == 0 || y.kind == 0
                                    ? "a chip select is a pin of its own (one chain, nothing else)"
                                : x.kind == 3 || y.kind == 3
                                    ? "an SPI pin is a pin of its own (chains may share one as the same sck/mosi/miso_pin=)"
                                    : "a chip output (BUSY, FLAG) and a chip input (SW, STCK, STBY_RST) cannot share a pin";
        return fail("pin " + to_string(x.pin) + " is " + x.key + "= " + where + " and " + y.key + "= here: " + why);
      }
    }
    return true;
  }

  // spi= without bus=: the bus of another chain on that controller, else a bus of its own. One
  // bus, one controller name; a chain with cs_pin= and without cs= takes a free chip select.
  bool place_on_bus(const BoardConfig& cfg, ChainConfig& chain, bool bus_given, bool cs_given) {
    if (!chain.pins.spi.empty()) {
      bool found = false;
      for (std::size_t i = 0; i < cfg.chains.size() && !found; ++i) {
        const ChainConfig& c = cfg.chains[i];
        if (c.pins.spi != chain.pins.spi) continue;
        found = true;
        if (!bus_given)
          chain.bus = c.bus;
        else if (c.bus != chain.bus)
          return fail("spi=" + chain.pins.spi + " is bus " + std::to_string(c.bus) + " in clause " +
                      std::to_string(chain_clause[i]) + " and bus " + std::to_string(chain.bus) +
                      " here: one controller drives one bus");
      }
      if (!found && !bus_given) {
        std::set<unsigned> used;
        for (const auto& c : cfg.chains) used.insert(c.bus);
        chain.bus = 0;
        while (used.count(chain.bus)) ++chain.bus;
      }
      for (std::size_t i = 0; i < cfg.chains.size(); ++i) {
        const ChainConfig& c = cfg.chains[i];
        if (c.bus == chain.bus && !c.pins.spi.empty() && c.pins.spi != chain.pins.spi)
          return fail("bus " + std::to_string(chain.bus) + " is spi=" + c.pins.spi + " in clause " +
                      std::to_string(chain_clause[i]) + " and spi=" + chain.pins.spi +
                      " here: one bus has one controller (give this chain its own bus=)");
      }
    }
    if (chain.pins.cs && !cs_given) {
      std::set<unsigned> used;
      for (const auto& c : cfg.chains)
        if (c.bus == chain.bus) used.insert(c.cs);
      chain.cs = 0;
      while (used.count(chain.cs) && chain.cs < 255) ++chain.cs;
    }
    return true;
  }

  // A word that is not key=value: say what was probably meant.
  bool fail_bare_word(std::string_view w) {
    const std::string q = quoted_text(w);
    if (w.front() == '=') return fail(q + " has no key before '=' (write key=value, without blanks around '=')");
    if (lookup_variant(w)) return fail("expected key=value, got " + q + " (did you mean chips=" + std::string(w) + "?)");
    if (w == "virtual" || w == "wall") return fail("expected key=value, got " + q + " (did you mean time=" + std::string(w) + "?)");
    if (const KeySpec* k = find_key(w))
      return fail(std::string(k->name) + " needs a value written right after '=', without blanks: e.g. " +
                  std::string(k->example));
    return fail("expected key=value, got " + q);
  }

  // axis.K=ITEMS: the mechanics behind chip K of this clause's chain.
  bool parse_axis_word(std::string_view key, std::string_view value, std::vector<std::pair<std::size_t, AxisSpec>>& axes) {
    std::size_t k = 0;
    if (!parse_uint(key.substr(5), k, 0, kMaxChipsPerChain - 1))
      return fail("axis key " + quoted_text(key) + " needs a chip number: axis.K= with K from 0 to 255 (e.g. axis.0=stops=0..256000)");
    for (const auto& [other, spec] : axes)
      if (other == k) return fail(std::string(key) + "= is given twice in this clause");
    if (value.empty()) return fail(std::string(key) + "= has no value (e.g. axis.0=default or axis.0=stops=0..256000)");
    AxisSpec spec;
    if (const std::string e = parse_axis_spec(value, spec); !e.empty()) return fail(std::string(key) + ": " + e);
    axes.emplace_back(k, std::move(spec));
    return true;
  }

  bool parse_clause(std::string_view clause, BoardConfig& cfg) {
    const auto words = split_words(clause);
    std::vector<std::pair<std::size_t, AxisSpec>> axes;
    std::vector<std::pair<const KeySpec*, std::string_view>> settings;
    std::map<std::string_view, std::string_view> in_clause;
    const KeySpec* first_chain_key = nullptr;
    bool is_chain = false;
    for (auto w : words) {
      for (char c : w)
        if (is_control(static_cast<unsigned char>(c)))
          return fail("control character in " + quoted_text(w) + " (a board description is plain text)");
      const std::size_t eq = w.find('=');
      if (eq == std::string_view::npos || eq == 0) return fail_bare_word(w);
      const std::string_view key = w.substr(0, eq), value = w.substr(eq + 1);
      if (key.substr(0, 5) == "axis.") {
        if (!parse_axis_word(key, value, axes)) return false;
        continue;
      }
      const KeySpec* spec = find_key(key);
      if (spec == nullptr) {
        std::string near = key_suggestion(key);
        // "axsi.0", "axes.1": a misspelt axis.K (the chip's number kept).
        if (const std::size_t dot = key.find('.'); near.empty() && dot != std::string_view::npos &&
                                                     closest_names(key.substr(0, dot), {"axis"}) == "axis")
          near = "axis" + std::string(key.substr(dot));
        return fail("unknown key " + quoted_text(key) + (near.empty() ? "" : ": did you mean " + near + "=?") +
                    " (chain keys: " + key_list(Scope::chain) + ", axis.K; board-wide: " + key_list(Scope::board) + ")");
      }
      if (auto it = in_clause.find(spec->name); it != in_clause.end())
        return fail(std::string(key) + "= is given twice in this clause (" + quoted_text(it->second) + ", then " +
                    quoted_text(value) + ")");
      in_clause[spec->name] = value;
      if (value.empty()) return fail(std::string(key) + "= has no value (e.g. " + std::string(spec->example) + ")");
      if (spec->scope == Scope::chain && !first_chain_key) first_chain_key = spec;
      if (spec->name == "chips") is_chain = true;
      settings.emplace_back(spec, value);
    }
    if (first_chain_key && !is_chain)
      return fail(std::string(first_chain_key->name) +
                  "= describes a chain: add chips= to this clause (e.g. 'bus=0 cs=0 chips=L6470')");
    if (!axes.empty() && !is_chain)
      return fail("axis." + std::to_string(axes.front().first) +
                  "= describes a chip of a chain: add chips= to this clause (e.g. 'chips=L6470 axis.0=default')");
    ChainConfig chain;
    for (const auto& [spec, value] : settings) {
      const bool ok = spec->scope == Scope::board ? set_board_key(*spec, value, cfg) : set_chain_key(*spec, value, chain);
      if (!ok) return false;
    }
    if (!is_chain) return true;
    if (!check_pin_lists(chain) || !place_on_bus(cfg, chain, in_clause.count("bus") != 0, in_clause.count("cs") != 0) ||
        !check_pin_uses(cfg, chain))
      return false;
    for (const auto& [k, spec] : axes)
      if (k >= chain.chips.size())
        return fail("axis." + std::to_string(k) + "= names chip " + std::to_string(k) + " but the chain has " +
                    std::to_string(chain.chips.size()) + " chip" + (chain.chips.size() == 1 ? "" : "s") + " (0 to " +
                    std::to_string(chain.chips.size() - 1) + ")");
    std::sort(axes.begin(), axes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    chain.axes = std::move(axes);
    if (cfg.chains.size() >= kMaxChains) return fail("a board holds at most 256 chains");
    if (chain.path.empty()) chain.path = "/dev/spidev" + std::to_string(chain.bus) + "." + std::to_string(chain.cs);
    for (std::size_t i = 0; i < cfg.chains.size(); ++i) {
      const auto& c = cfg.chains[i];
      if (c.path == chain.path)
        return fail("two chains on " + chain.path + " (clause " + std::to_string(chain_clause[i]) + " and this one)");
      if (c.gpiochip && chain.gpiochip && *c.gpiochip == *chain.gpiochip && chain_gpiochip_given[i])
        return fail("two chains on /dev/gpiochip" + std::to_string(*chain.gpiochip) + " (clause " +
                    std::to_string(chain_clause[i]) + " and this one)");
    }
    chain_clause.push_back(clause_no);
    chain_line.push_back(line_no);
    chain_gpiochip_given.push_back(in_clause.count("gpiochip") != 0);
    cfg.chains.push_back(std::move(chain));
    return true;
  }

  // A chip pin given to a chip that has no such pin (dir_pin= for an L6470, sw_pin= for an
  // L6474): refused, once numbering= is known. One pin for the whole chain needs one chip with it.
  bool check_chip_pins(const BoardConfig& cfg) {
    for (std::size_t i = 0; i < cfg.chains.size(); ++i) {
      const ChainConfig& c = cfg.chains[i];
      const ChipNumbering numbers(cfg.numbering, c.chips.size());
      for (unsigned p = 0; p < kPinsPerChip; ++p) {
        const Pin pin = static_cast<Pin>(p);
        const ChipPinList& list = c.pins.chip[p];
        const auto has = [&](std::size_t index) { return variant_has_pin(*c.chips[index], pin); };
        std::optional<std::size_t> lacking;  // a chain index
        if (list.size() == 1 && list[0]) {
          bool any = false;
          for (std::size_t k = 0; k < c.chips.size(); ++k) any = any || has(k);
          if (!any) lacking = 0;
        } else {
          for (std::size_t u = 0; u < list.size() && !lacking; ++u)
            if (list[u] && !has(numbers.index_of(u))) lacking = numbers.index_of(u);
        }
        if (!lacking) continue;
        clause_no = chain_clause[i];
        line_no = chain_line[i];
        const std::string key = pin_key(pin);
        std::string owners;  // "a pin of L6474"
        for (const Variant* v : all_variants())
          if (variant_has_pin(*v, pin)) owners += (owners.empty() ? "" : ", ") + std::string(v->name);
        if (list.size() == 1)
          return fail(key + "= names a pin for this chain, but none of its chips has a " + pin_name(pin) +
                      " pin (a pin of " + owners + ")");
        return fail(key + "= gives " + numbers.label(*lacking) + " a pin, but it is an " +
                    std::string(c.chips[*lacking]->name) + ", which has no " + pin_name(pin) + " pin (a pin of " +
                    owners + "): write '-' for it");
      }
    }
    return true;
  }

  // Chains without gpiochip= get the lowest numbers no chain asked for, in order.
  bool assign_default_gpiochips(BoardConfig& cfg) {
    std::set<unsigned> used;
    for (std::size_t i = 0; i < cfg.chains.size(); ++i)
      if (chain_gpiochip_given[i] && cfg.chains[i].gpiochip) used.insert(*cfg.chains[i].gpiochip);
    unsigned n = 0;
    for (std::size_t i = 0; i < cfg.chains.size(); ++i) {
      if (chain_gpiochip_given[i]) continue;
      while (used.count(n)) ++n;
      if (n > kMaxGpiochip) {
        clause_no = chain_clause[i];
        line_no = chain_line[i];
        return fail("no free gpiochip number left (0..1023): write gpiochip=none");
      }
      cfg.chains[i].gpiochip = n;
      used.insert(n);
    }
    return true;
  }
};

}  // namespace

namespace {

// shown_text, and whether it had to cut.
std::string show(std::string_view text, std::size_t max_chars, bool& cut) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(std::min(text.size(), max_chars) + 4);
  cut = false;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    const bool escape = is_control(c) || c >= 0x80 || c == '\\';
    if (out.size() + (escape ? 4 : 1) > max_chars) {
      cut = true;
      out += "\u2026";
      break;
    }
    if (escape) {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    } else {
      out += ch;
    }
  }
  return out;
}

}  // namespace

std::string shown_text(std::string_view text, std::size_t max_chars) {
  bool cut = false;
  return show(text, max_chars, cut);
}

std::string quoted_text(std::string_view text) {
  bool cut = false;
  std::string out = "'" + show(text, kQuotedTextChars, cut) + "'";
  if (cut) out += " (" + std::to_string(text.size()) + " bytes)";
  return out;
}

ParseResult parse_board_config(std::string_view text, std::string_view origin) {
  Parser p{};
  p.origin = origin;
  if (text.size() > kMaxBytes)
    return {std::nullopt, {"l6470emu: config " + shown_text(origin, 200) +
                           ": longer than 1 MiB (a board description is a few lines)"}};
  BoardConfig cfg;
  // Lines end at newlines and '#' comments run to the end of the line; ';' separates clauses
  // within a line. Clauses are numbered through the whole text.
  p.show_line = text.find('\n') != std::string_view::npos;
  std::size_t line_start = 0;
  while (line_start <= text.size()) {
    ++p.line_no;
    std::size_t line_end = text.find('\n', line_start);
    if (line_end == std::string_view::npos) line_end = text.size();
    std::string_view line = text.substr(line_start, line_end - line_start);
    line = line.substr(0, line.find('#'));
    std::size_t start = 0;
    while (start <= line.size()) {
      std::size_t end = line.find(';', start);
      if (end == std::string_view::npos) end = line.size();
      const std::string_view clause = trim(line.substr(start, end - start));
      ++p.clause_no;
      if (!clause.empty() && !p.parse_clause(clause, cfg)) return {std::nullopt, {p.error}};
      start = end + 1;
    }
    line_start = line_end + 1;
  }
  if (!p.assign_default_gpiochips(cfg) || !p.check_chip_pins(cfg)) return {std::nullopt, {p.error}};
  if (cfg.chains.empty() && cfg.socket.empty())
    return {std::nullopt, {"l6470emu: config " + shown_text(origin, 200) +
                           ": no chain (write e.g. 'bus=0 cs=0 chips=L6470' or 'socket=PATH')"}};
  return {std::move(cfg), {}};
}

std::string chip_list_text(const std::vector<const Variant*>& chips) {
  std::string out;
  for (std::size_t i = 0; i < chips.size();) {
    std::size_t run = 1;
    while (i + run < chips.size() && chips[i + run] == chips[i]) ++run;
    if (i) out += ',';
    if (run > 1) out += std::to_string(run) + "x";
    out += chips[i]->name;
    i += run;
  }
  return out;
}

std::string describe_board_config(const BoardConfig& config) {
  std::ostringstream o;
  for (const auto& c : config.chains) {
    o << "bus=" << c.bus << " cs=" << c.cs << " path=" << c.path << " chips=" << chip_list_text(c.chips);
    o << " gpiochip=" << (c.gpiochip ? std::to_string(*c.gpiochip) : std::string("none")) << " speed=" << c.max_speed_hz
      << " mode=" << unsigned{c.mode} << " bufsiz=" << c.bufsiz;
    for (const auto& [k, spec] : c.axes) {
      const std::string items = describe_axis_spec(spec);
      o << " axis." << k << "=" << (items.empty() ? "default" : items);
    }
    if (c.pins.cs) o << " cs_pin=" << to_string(*c.pins.cs);
    if (c.pins.sck) o << " sck_pin=" << to_string(*c.pins.sck);
    if (c.pins.mosi) o << " mosi_pin=" << to_string(*c.pins.mosi);
    if (c.pins.miso) o << " miso_pin=" << to_string(*c.pins.miso);
    for (unsigned p = 0; p < kPinsPerChip; ++p)
      if (!c.pins.chip[p].empty()) o << " " << pin_key(static_cast<Pin>(p)) << "=" << pin_list_text(c.pins.chip[p]);
    if (!c.pins.spi.empty()) o << " spi=" << c.pins.spi;
    o << "\n";
  }
  // scale= only means something on the wall clock, idle= only in virtual time.
  if (config.time.virtual_time) {
    o << "time=virtual";
    const TimeConfig defaults;
    if (config.time.idle_ns == 0)
      o << " idle=off";
    else if (config.time.idle_ns != defaults.idle_ns)
      o << " idle=" << shortest(static_cast<double>(config.time.idle_ns) / 1e9);
  } else {
    o << "time=wall scale=" << shortest(config.time.scale);
  }
  o << "\n";
  if (config.log != "stderr") o << "log=" << config.log << "\n";
  if (!config.socket.empty()) o << "socket=" << config.socket << "\n";
  if (!config.trace.empty()) o << "trace=" << config.trace << "\n";
  if (config.numbering != NumberFrom::miso) o << "numbering=" << to_string(config.numbering) << "\n";
  if (config.check.level != CheckLevel::warn) o << "check=" << to_string(config.check.level) << "\n";
  if (!config.check.allowed.empty()) o << "check.allow=" << rule_list(config.check.allowed) << "\n";
  const FirmwareTiming fw_defaults;
  const FirmwareTiming& fw = config.firmware;
  std::string firmware;
  if (fw.call_ticks != fw_defaults.call_ticks) firmware += " call_time=" + duration_text(fw.call_ticks);
  if (fw.loop_ticks != fw_defaults.loop_ticks) firmware += " loop_time=" + duration_text(fw.loop_ticks);
  if (fw.limit_ticks != fw_defaults.limit_ticks) firmware += " limit=" + duration_text(fw.limit_ticks);
  if (fw.apb_clock_hz != fw_defaults.apb_clock_hz) firmware += " apb_clock=" + std::to_string(fw.apb_clock_hz);
  if (!firmware.empty()) o << firmware.substr(1) << "\n";
  return o.str();
}

}  // namespace l6470emu
