// Parser of the board description (L6470EMU_CHAIN, config files, `serve --chain`).
#include "linux/config.hpp"

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <utility>

namespace l6470emu {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split_words(std::string_view s) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') ++j;
    if (j > i) words.push_back(s.substr(i, j - i));
    i = j;
  }
  return words;
}

template <typename T>
bool parse_uint(std::string_view s, T& out, unsigned long long max) {
  unsigned long long v = 0;
  const auto* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, v, 10);
  if (ec != std::errc{} || p != end || s.empty() || v > max) return false;
  out = static_cast<T>(v);
  return true;
}

bool parse_double(std::string_view s, double& out) {
  std::string text(s);
  char* end = nullptr;
  errno = 0;
  out = std::strtod(text.c_str(), &end);
  return !text.empty() && errno == 0 && end == text.c_str() + text.size();
}

struct Parser {
  std::string_view origin;
  std::string error;
  unsigned clause_no = 0;

  bool fail(std::string what) {
    if (error.empty()) {
      std::ostringstream o;
      o << "l6470emu: config " << origin << ", clause " << clause_no << ": " << what;
      error = o.str();
    }
    return false;
  }

  // "L6470", "3xL6470", "L6470x3", "3*L6470", "L6470*3"
  bool parse_chip_list(std::string_view list, std::vector<const Variant*>& chips) {
    std::size_t start = 0;
    while (start <= list.size()) {
      std::size_t comma = list.find(',', start);
      if (comma == std::string_view::npos) comma = list.size();
      std::string_view item = trim(list.substr(start, comma - start));
      if (item.empty()) return fail("empty entry in chips=" + std::string(list));
      unsigned count = 1;
      std::string_view name = item;
      for (char sep : {'x', '*'}) {
        const std::size_t at = item.find(sep);
        if (at == std::string_view::npos || at == 0 || at + 1 >= item.size()) continue;
        unsigned n = 0;
        if (parse_uint(item.substr(0, at), n, 256) && lookup_variant(item.substr(at + 1))) {
          count = n;
          name = item.substr(at + 1);
          break;
        }
        if (parse_uint(item.substr(at + 1), n, 256) && lookup_variant(item.substr(0, at))) {
          count = n;
          name = item.substr(0, at);
          break;
        }
      }
      const Variant* v = lookup_variant(name);
      if (v == nullptr)
        return fail("unknown chip variant '" + std::string(name) + "' (known: " + known_variant_names() + ")");
      if (count == 0) return fail("chip count 0 in '" + std::string(item) + "'");
      for (unsigned i = 0; i < count; ++i) chips.push_back(v);
      start = comma + 1;
    }
    if (chips.size() > 256) return fail("a chain holds at most 256 chips, not " + std::to_string(chips.size()));
    return true;
  }

  bool parse_clause(std::string_view clause, BoardConfig& cfg) {
    const auto words = split_words(clause);
    bool is_chain = false;
    for (auto w : words)
      if (w.substr(0, 6) == "chips=") is_chain = true;
    ChainConfig chain;
    bool have_gpiochip = false;
    for (auto w : words) {
      const std::size_t eq = w.find('=');
      if (eq == std::string_view::npos || eq == 0)
        return fail("expected key=value, got '" + std::string(w) + "'");
      const std::string_view key = w.substr(0, eq), value = w.substr(eq + 1);
      const std::string k(key), v(value);
      if (value.empty()) return fail("empty value for " + k);
      if (is_chain) {
        if (key == "bus") {
          if (!parse_uint(value, chain.bus, 32767)) return fail("bus must be a number 0..32767, not '" + v + "'");
        } else if (key == "cs") {
          if (!parse_uint(value, chain.cs, 255)) return fail("cs must be a number 0..255, not '" + v + "'");
        } else if (key == "path") {
          if (value.substr(0, 5) != "/dev/") return fail("path must be under /dev/, not '" + v + "'");
          chain.path = v;
        } else if (key == "chips") {
          if (!parse_chip_list(value, chain.chips)) return false;
        } else if (key == "gpiochip") {
          have_gpiochip = true;
          if (value == "none") {
            chain.gpiochip.reset();
          } else {
            unsigned n = 0;
            if (!parse_uint(value, n, 1023)) return fail("gpiochip must be a number or 'none', not '" + v + "'");
            chain.gpiochip = n;
          }
        } else if (key == "speed") {
          if (!parse_uint(value, chain.max_speed_hz, 1'000'000'000) || chain.max_speed_hz == 0)
            return fail("speed must be a frequency in Hz (1..1000000000), not '" + v + "'");
        } else if (key == "mode") {
          if (!parse_uint(value, chain.mode, 3)) return fail("mode must be 0..3, not '" + v + "'");
        } else if (key == "bufsiz") {
          if (!parse_uint(value, chain.bufsiz, 1u << 22) || chain.bufsiz == 0)
            return fail("bufsiz must be 1..4194304, not '" + v + "'");
        } else {
          return fail("unknown chain key '" + k + "' (keys: bus, cs, path, chips, gpiochip, speed, mode, bufsiz)");
        }
      } else {
        if (key == "time") {
          if (value == "wall")
            cfg.time.virtual_time = false;
          else if (value == "virtual")
            cfg.time.virtual_time = true;
          else
            return fail("time must be 'wall' or 'virtual', not '" + v + "'");
        } else if (key == "scale") {
          double s = 0;
          if (!parse_double(value, s) || !(s > 0) || s > 1e6) return fail("scale must be a number > 0 (and <= 1e6), not '" + v + "'");
          cfg.time.scale = s;
        } else if (key == "log") {
          cfg.log = v;
        } else if (key == "socket") {
          cfg.socket = v;
        } else if (key == "trace") {
          cfg.trace = v;
        } else if (key == "bus" || key == "cs" || key == "path" || key == "gpiochip") {
          return fail("chain key '" + k + "' without chips= in the same clause");
        } else {
          return fail("unknown key '" + k + "' (globals: time, scale, log, socket, trace; a chain needs chips=)");
        }
      }
    }
    if (!is_chain) return true;
    if (chain.path.empty()) chain.path = "/dev/spidev" + std::to_string(chain.bus) + "." + std::to_string(chain.cs);
    if (!have_gpiochip) {
      // Default: the k-th chain gets /dev/gpiochip<k>, skipping numbers already taken.
      std::set<unsigned> used;
      for (const auto& c : cfg.chains)
        if (c.gpiochip) used.insert(*c.gpiochip);
      unsigned n = 0;
      while (used.count(n)) ++n;
      chain.gpiochip = n;
    }
    for (const auto& c : cfg.chains) {
      if (c.path == chain.path) return fail("two chains on " + chain.path);
      if (c.gpiochip && chain.gpiochip && *c.gpiochip == *chain.gpiochip)
        return fail("two chains on /dev/gpiochip" + std::to_string(*chain.gpiochip));
    }
    cfg.chains.push_back(std::move(chain));
    return true;
  }
};

}  // namespace

ParseResult parse_board_config(std::string_view text, std::string_view origin) {
  Parser p{origin, {}, 0};
  BoardConfig cfg;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find_first_of(";\n", start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view clause = text.substr(start, end - start);
    const std::size_t hash = clause.find('#');
    if (hash != std::string_view::npos) clause = clause.substr(0, hash);
    clause = trim(clause);
    ++p.clause_no;
    if (!clause.empty() && !p.parse_clause(clause, cfg)) return {std::nullopt, {p.error}};
    start = end + 1;
  }
  if (cfg.chains.empty() && cfg.socket.empty()) {
    p.clause_no = 0;
    return {std::nullopt, {"l6470emu: config " + std::string(origin) +
                           ": no chain (write e.g. 'bus=0 cs=0 chips=L6470' or 'socket=PATH')"}};
  }
  return {std::move(cfg), {}};
}

ParseResult load_board_config_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) return {std::nullopt, {"l6470emu: config file " + path + ": cannot be read"}};
  std::stringstream s;
  s << in.rdbuf();
  return parse_board_config(s.str(), path);
}

std::string describe_board_config(const BoardConfig& config) {
  std::ostringstream o;
  for (const auto& c : config.chains) {
    o << "bus=" << c.bus << " cs=" << c.cs << " path=" << c.path << " chips=";
    for (std::size_t i = 0; i < c.chips.size(); ++i) o << (i ? "," : "") << c.chips[i]->name;
    o << " gpiochip=" << (c.gpiochip ? std::to_string(*c.gpiochip) : std::string("none")) << " speed=" << c.max_speed_hz
      << " mode=" << unsigned{c.mode} << " bufsiz=" << c.bufsiz << "\n";
  }
  o << "time=" << (config.time.virtual_time ? "virtual" : "wall") << " scale=" << config.time.scale << "\n";
  if (!config.trace.empty()) o << "trace=" << config.trace << "\n";
  return o.str();
}

}  // namespace l6470emu
