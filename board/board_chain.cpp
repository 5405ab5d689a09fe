// build_chips / describe_recorded_chain / parse_chain_description.
#include "board/board_chain.hpp"

namespace l6470emu {

std::vector<Chip> build_chips(const ChainConfig& chain, NumberFrom numbering) {
  std::vector<Chip> chips;
  chips.reserve(chain.chips.size());
  for (const Variant* v : chain.chips) chips.emplace_back(*v);
  // axis.K counts chips as the board's numbering= does.
  const ChipNumbering axis_numbers(numbering, chips.size());
  for (const auto& [k, spec] : chain.axes) chips.at(axis_numbers.index_of(k)).attach_axis(spec);
  return chips;
}

Chain build_chain(const ChainConfig& chain, NumberFrom numbering) { return Chain(build_chips(chain, numbering)); }

std::string describe_recorded_chain(const BoardConfig& board, const ChainConfig& chain) {
  BoardConfig one = board;
  one.chains = {chain};
  // Where the run's output went is no part of the world it ran in.
  one.log = "stderr";
  one.socket.clear();
  one.trace.clear();
  return describe_board_config(one);
}

ChainDescription parse_chain_description(std::string_view text, std::string_view origin) {
  ChainDescription d;
  ParseResult r = parse_board_config(text, origin);
  if (!r.config) {
    d.error = r.error.message;
    return d;
  }
  if (r.config->chains.size() != 1) {
    d.error = "l6470emu: config " + shown_text(origin, 200) + ": describes " + std::to_string(r.config->chains.size()) +
              " chains; a trace runs through one (keep its clause and the board-wide keys)";
    return d;
  }
  d.board = std::move(r.config);
  return d;
}

}  // namespace l6470emu
