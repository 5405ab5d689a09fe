// world_for_header: the explicit description, the trace's own or a guess, checked.
#include "tools/trace_world.hpp"

#include <stdexcept>

#include "board/board_chain.hpp"
#include "daisychain/chain_spec.hpp"
#include "linux/board_config_file.hpp"

namespace l6470emu {
namespace {

/// A config error without the "l6470emu: " the parser puts in front (the tools add their own).
std::string without_prefix(std::string message) {
  constexpr std::string_view kPrefix = "l6470emu: ";
  if (message.rfind(kPrefix, 0) == 0) message.erase(0, kPrefix.size());
  return message;
}

BoardConfig board_of_variants(std::vector<const Variant*> variants) {
  BoardConfig b;
  ChainConfig c;
  c.chips = std::move(variants);
  c.path = "/dev/spidev0.0";
  b.chains.push_back(std::move(c));
  return b;
}

std::vector<const Variant*> variants_of(const std::string& spec, const std::string& file, std::uint64_t line) {
  try {
    return parse_chain_spec(spec);
  } catch (const std::invalid_argument& e) {
    throw TraceError(file, line, e.what());
  }
}

BoardConfig description_of(const std::string& text, const std::string& origin, const std::string& file,
                           std::uint64_t line) {
  ChainDescription d = parse_chain_description(text, origin);
  if (!d.board) throw TraceError(file, line, without_prefix(d.error));
  return std::move(*d.board);
}

}  // namespace

Chain TraceWorld::make_chain() const { return build_chain(chain(), board.numbering); }

std::string TraceWorld::summary() const {
  std::string s = chain_spec_of(chain().chips);
  if (!chain().axes.empty()) {
    s += chain().axes.size() == 1 ? " with an axis behind chip " : " with axes behind chips ";
    for (std::size_t i = 0; i < chain().axes.size(); ++i)
      s += (i ? "," : "") + std::to_string(chain().axes[i].first);
  }
  return s;
}

std::string TraceWorld::board_text() const { return describe_board_config(board); }

std::string TraceWorld::override_note(const std::string& trace_name) const {
  if (!overrides) return "";
  return "the trace's own description (" + overridden + ") is not used: " + trace_name + " runs through " + summary() +
         " (" + how + ")";
}

TraceWorld world_for_header(const WorldOptions& options, const TraceHeader& header,
                            const std::function<std::vector<const Variant*>(std::string& how)>& guess) {
  TraceWorld w;
  const bool own = !header.board.empty() || !header.chain.empty();
  if (!options.chain.empty() && !options.board_file.empty())
    throw std::invalid_argument("--chain and --board both describe the chain: give one of them");
  if (!options.board_file.empty()) {
    const ParseResult r = load_board_config_file(options.board_file);
    if (!r.config) throw TraceError(options.board_file, 0, without_prefix(r.error.message));
    if (r.config->chains.size() != 1)
      throw TraceError(options.board_file, 0,
                       "describes " + std::to_string(r.config->chains.size()) +
                           " chains; a trace runs through one (keep its clause and the board-wide keys)");
    w.board = *r.config;
    w.how = "from --board " + options.board_file;
  } else if (!options.chain.empty()) {
    if (options.chain.find('=') != std::string::npos) {
      w.board = description_of(options.chain, "--chain", "--chain", 0);
      w.how = "from the description given with --chain";
    } else {
      w.board = board_of_variants(variants_of(options.chain, "--chain", 0));
      w.how = "from --chain";
    }
  } else if (!header.board.empty()) {
    w.board = description_of(header.board, header.name + ":" + std::to_string(header.board_line) + " (board lines)",
                             header.name, header.board_line);
    w.how = "from the trace's board description";
    if (!header.chain.empty()) {
      const std::vector<const Variant*> listed = variants_of(header.chain, header.name, header.chain_line);
      if (listed != w.chain().chips)
        throw TraceError(header.name, header.chain_line,
                         "the chain line (" + header.chain + ") and the board lines (chips " +
                             chain_spec_of(w.chain().chips) + ") describe different chains");
    }
    return w;
  } else if (!header.chain.empty()) {
    w.board = board_of_variants(variants_of(header.chain, header.name, header.chain_line));
    w.how = "from the trace";
    return w;
  } else {
    if (!guess) throw std::invalid_argument("the trace names no chain: give one (e.g. --chain 3*L6470)");
    std::string how;
    w.board = board_of_variants(guess(how));
    w.how = how;
    return w;
  }
  // An explicit description: it replaces the trace's own, if it had one.
  if (own) {
    w.overrides = true;
    w.overridden = !header.board.empty() ? "its board lines, from line " + std::to_string(header.board_line)
                                         : "its chain line: " + header.chain;
  }
  return w;
}

TraceWorld world_for_trace(const WorldOptions& options, const TraceFile& file) {
  return world_for_header(options, file.header(), [&file](std::string& how) {
    return chain_for_trace("", file, how);
  });
}

}  // namespace l6470emu
