// Pulse trains on input pins (a timer's PWM output on STCK): their closed-form edge times, and
// how a chain brought to a tick takes the edges up to it, in bulk where nothing needs them one
// by one. The timers that make trains are the fronts' (firmware/timers.cpp).
#include <algorithm>

#include "board/board_internal.hpp"

namespace l6470emu {

// ---------------------------------------------------------------- PulseTrain

Tick PulseTrain::tick_at(std::uint64_t counts) const {
  return start + static_cast<Tick>(static_cast<unsigned __int128>(counts) * kTicksPerSecond / clock_hz);
}

std::uint64_t PulseTrain::edges_through(Tick tick, std::uint64_t offset_counts) const {
  if (tick < start) return 0;
  // Edge k is at or before `tick` when floor((k × period + offset) × TPS / clock) <= tick - start,
  // that is when k × period + offset < limit = ceil((tick - start + 1) × clock / TPS).
  const auto span = static_cast<unsigned __int128>(tick - start + 1) * clock_hz;
  const auto limit = (span + kTicksPerSecond - 1) / kTicksPerSecond;
  if (limit <= offset_counts) return 0;
  unsigned __int128 n = (limit - 1 - offset_counts) / period_counts + 1;
  n = n > first ? n - first : 0;  // the periods before the first pulse made have none
  if (count && n > count) return count;
  return n > ~std::uint64_t{0} ? ~std::uint64_t{0} : static_cast<std::uint64_t>(n);
}

// ---------------------------------------------------------------- the board's trains

Tick Board::ChainState::Train::next_edge() const {
  if (train.count && rises + falls >= 2 * train.count) return kNever;
  return rises == falls ? train.rise_tick(rises) : train.fall_tick(falls);
}

void Board::run_trains(ChainState& c, Tick target) {
  using Train = ChainState::Train;
  // Every edge at its tick where something must see each one: a recording, an axis, the SYNC
  // clock a step-clock chip puts out on BUSY\SYNC, a pin other than STCK.
  auto one_by_one = [&](const Train& t) {
    const Chip& chip = c.chain.chip(t.chip);
    return c.recorder || t.pin != Pin::STCK || chip.has_axis() || chip.sync_clock_on();
  };
  auto apply_edge = [&](Train& t, bool level) {
    if (c.wired) c.wire[t.chip][static_cast<unsigned>(t.pin)] = level;
    apply_input(c, t.chip, t.pin, level);
    (level ? t.rises : t.falls) += 1;
    ++train_counts_.single_edges;
  };
  // Edges that must come one at a time, in time order across the chain's trains.
  for (;;) {
    Train* first = nullptr;
    Tick at = kNever;
    for (Train& t : c.trains)
      if (one_by_one(t) && t.next_edge() < at) {
        at = t.next_edge();
        first = &t;
      }
    if (!first || at > target) break;
    if (at > c.chain.now()) advance_chain(c, at);
    apply_edge(*first, first->rises == first->falls);
    emit_changes(c, c.chain.now());
  }
  if (target > c.chain.now()) advance_chain(c, target);
  // The rest in bulk: nothing in the chip decides differently between two STCK pulses.
  bool changed = false;
  for (Train& t : c.trains) {
    if (one_by_one(t)) continue;
    const std::uint64_t rises = t.train.rises_through(target), falls = t.train.falls_through(target);
    if (rises == t.rises && falls == t.falls) continue;
    changed = true;
    // Pulses that rose and fell since the last look; a pulse left high before falls first.
    const std::uint64_t whole = falls > t.rises ? falls - t.rises : 0;
    Chip& chip = c.chain.chip(t.chip);
    if (coverage_) {
      coverage_->input(c.index, t.chip, t.pin, true);
      coverage_->input(c.index, t.chip, t.pin, false);
    }
    if (falls > t.falls) chip.stck_pulses(whole);
    if (rises > falls && rises > t.rises) chip.set_stck_pin(true);  // a pulse high at `target`
    train_counts_.bulk_pulses += rises > t.rises ? rises - t.rises : 0;
    t.rises = rises;
    t.falls = falls;
    if (c.wired) c.wire[t.chip][static_cast<unsigned>(t.pin)] = rises > falls;
  }
  if (changed) {
    c.touched = true;
    c.prediction_valid = false;
    emit_changes(c, c.chain.now());
  }
  std::erase_if(c.trains, [&](const Train& t) { return t.next_edge() == kNever && (c.add_train_rises(t), true); });
}

bool Board::drive_pulse_train(std::size_t chain, std::size_t chip, Pin pin, const PulseTrain& train) {
  if (chain >= chains_.size() || pin_is_chip_output(pin) || !train.valid()) return false;
  ChainState& c = *chains_[chain];
  if (chip >= c.chain.size() || !variant_has_pin(c.chain.peek_chip(chip).variant(), pin)) return false;
  catch_up(c);
  if (train.rise_tick(0) < c.chain.now()) return false;
  // A train already on the pin keeps the pulses that rise before the new one starts (a timer
  // whose new period takes effect at its update event), and no later one.
  bool replaced = false;
  std::uint64_t made_rises = 0, made_falls = 0;  // edges the old train made from the new one's start on
  for (auto it = c.trains.begin(); it != c.trains.end();) {
    if (it->chip != chip || it->pin != pin) {
      ++it;
      continue;
    }
    replaced = true;
    const Tick from = train.rise_tick(0);
    const std::uint64_t keep = from ? it->train.rises_through(from - 1) : 0;
    // A new train starting now takes over the edges the old one made now (its own).
    made_rises += it->rises > keep ? it->rises - keep : 0;
    made_falls += it->falls > keep ? it->falls - keep : 0;
    it->rises = std::min(it->rises, keep);
    it->falls = std::min(it->falls, keep);
    if (keep == 0 || (it->rises == keep && it->falls == keep)) {
      c.add_train_rises(*it);
      it = c.trains.erase(it);
      continue;
    }
    it->train.count = keep;
    ++it;
  }
  if (!replaced) set_input(chain, chip, pin, false);
  // Edges at the board's time already made by the train it replaces are not made twice.
  const Tick now = c.chain.now();
  c.trains.push_back(ChainState::Train{chip, pin, train, std::min(train.rises_through(now), made_rises),
                                       std::min(train.falls_through(now), made_falls)});
  catch_up(c);  // a train starting now has its first edge now
  emit_changes(c, c.chain.now());
  return true;
}

bool Board::stop_pulse_train(std::size_t chain, std::size_t chip, Pin pin, bool level) {
  if (chain >= chains_.size()) return false;
  ChainState& c = *chains_[chain];
  auto on_pin = [&](const ChainState::Train& t) { return t.chip == chip && t.pin == pin; };
  if (std::none_of(c.trains.begin(), c.trains.end(), on_pin)) return false;
  catch_up(c);
  std::erase_if(c.trains, [&](const ChainState::Train& t) { return on_pin(t) && (c.add_train_rises(t), true); });
  set_input(chain, chip, pin, level);
  emit_changes(c, c.chain.now());
  return true;
}

std::uint64_t Board::pulse_train_rises(std::size_t chain, std::size_t chip, Pin pin) {
  if (chain >= chains_.size()) return 0;
  ChainState& c = *chains_[chain];
  catch_up(c);
  std::uint64_t rises = 0;
  for (const auto& [where, n] : c.train_rises)
    if (where == std::pair{chip, pin}) rises += n;
  for (const ChainState::Train& t : c.trains)
    if (t.chip == chip && t.pin == pin) rises += t.rises;
  return rises;
}

}  // namespace l6470emu
