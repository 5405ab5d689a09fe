// DivergenceWatch: the byte and pin comparisons of a replay, keeping the first difference.
#include "daisychain/divergence.hpp"

#include <cstdio>

#include "daisychain/explain.hpp"
#include "daisychain/protocol_tracker.hpp"

namespace l6470emu {

DivergenceWatch::DivergenceWatch(std::string name, ChipNumbering numbering)
    : name_(std::move(name)), numbering_(numbering) {}

void DivergenceWatch::frame(const TraceEvent& e, std::span<const std::uint8_t> emulated) {
  ++frames_;
  if (e.miso.empty()) return;
  std::size_t first_bad = e.mosi.size();
  std::size_t bad = 0;
  for (std::size_t i = 0; i < e.mosi.size() && i < emulated.size(); ++i)
    if (e.miso_byte_known(i) && e.miso[i] != emulated[i]) {
      if (bad++ == 0) first_bad = i;
    }
  if (bad == 0) return;
  ++frames_diverged_;
  if (first_.found) return;
  std::string what = "MISO byte " + std::to_string(first_bad) + " expected " + hex_value(e.miso[first_bad], 8) +
                     ", emulated " + hex_value(emulated[first_bad], 8);
  if (bad > 1) what += " (and " + std::to_string(bad - 1) + " more bytes differ)";
  // MISO byte i of a frame comes out of chip i; past the chain's length it is MOSI coming back.
  found(e, first_bad < numbering_.chips() ? first_bad : FirstDivergence::kNoChip, std::move(what));
}

bool observed_level(const Chip& chip, TracePin pin) {
  switch (pin) {
    case TracePin::BUSY: return chip.busy_sync_pin();
    case TracePin::FLAG: return chip.flag_pin();
    default: return chip.sw_pin();
  }
}

void DivergenceWatch::observation(const TraceEvent& e, bool emulated) {
  if (!e.is_observation()) return;
  if ((e.value != 0) == emulated) return;
  ++pins_diverged_;
  if (first_.found) return;
  auto level = [](bool l) { return std::string(l ? "high" : "low"); };
  found(e, e.chip, std::string(to_string(e.pin)) + (e.pin == TracePin::SW_AXIS ? " (driven by its axis)" : "") + " expected " + level(e.value != 0) + ", emulated " + level(emulated));
}

void DivergenceWatch::found(const TraceEvent& e, std::size_t chip, std::string what) {
  first_.found = true;
  first_.frame = frames_;
  first_.line = e.line;
  first_.repetition = e.repetition;
  first_.tick = e.tick;
  first_.seconds = display_seconds(e.tick, e.source_time);
  first_.chip = chip;
  first_.number = chip == FirstDivergence::kNoChip ? chip : numbering_.number_of(chip);
  first_.what = std::move(what);
  std::string where = e.line ? name_ + ":" + std::to_string(e.line) : name_;
  if (e.repetition) where += " (repetition " + std::to_string(e.repetition) + ")";
  char t[64];
  std::snprintf(t, sizeof t, "t=%.6f s", first_.seconds);
  first_.summary = where + ": " + (e.kind == TraceEventKind::frame ? "frame " : "after frame ") +
                   std::to_string(first_.frame) + " at " + t + ": " +
                   (chip == FirstDivergence::kNoChip ? std::string("bytes past the chain") : numbering_.label(chip)) +
                   ": " + first_.what;
}

std::string DivergenceWatch::counts() const {
  if (!first_.found) return "matched";
  std::string s = "DIVERGED in " + std::to_string(frames_diverged_) + (frames_diverged_ == 1 ? " frame" : " frames");
  if (pins_diverged_) s += " and " + std::to_string(pins_diverged_) + (pins_diverged_ == 1 ? " pin level" : " pin levels");
  return s;
}

}  // namespace l6470emu
