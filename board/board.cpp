// Board: the chains, their buses, the pins and their edges, and time.
#include <algorithm>
#include <array>
#include <climits>
#include <sstream>

#include "board/board_chain.hpp"
#include "board/board_internal.hpp"

namespace l6470emu {

Board::Board(const BoardConfig& config, LineSink log, HostClock& host)
    : log_(std::move(log)), sanitizer_(config.check, log_), time_(config.time, host), numbering_(config.numbering),
      config_(config) {
  for (const ChainConfig& cc : config.chains) {
    auto cs = std::make_unique<ChainState>(cc, build_chips(cc, numbering_));
    cs->name = cc.path.substr(cc.path.rfind('/') + 1);
    cs->index = chains_.size();
    cs->wired = cc.gpiochip.has_value();
    ChainState::PinLevels initial{};
    initial.fill(true);
    // SW open (pulled up), STBY_RST high (running), STCK and DIR low.
    initial[static_cast<unsigned>(Pin::STCK)] = false;
    initial[static_cast<unsigned>(Pin::DIR)] = false;
    cs->wire.assign(cs->chain.size(), initial);
    ChainState::PinLevels all_high{};
    all_high.fill(true);
    cs->last.assign(cs->chain.size(), all_high);
    cs->checker = std::make_unique<ChainChecker>(sanitizer_, cs->chain, cs->name, numbering_);
    cs->bus = std::make_unique<ChainBus>(cs->chain, cs->chain, *cs->checker);
    // The chips' diagnostics (WRONG_CMD, NOTPERF_CMD, dropped bits and answers) are rules the
    // sanitizer names: logged (rate-limited) under check=warn, the run's end under check=error.
    for (std::size_t k = 0; k < cs->chain.size(); ++k) {
      ChainChecker* checker = cs->checker.get();
      cs->chain.chip(k).set_diagnostic_sink([this, checker, chain = cs->index, k](const Diagnostic& d) {
        checker->chip_diagnostic(k, d);
        if (coverage_) coverage_->diagnostic(chain, k, d);
      });
    }
    cs->command_observers.resize(cs->chain.size());
    chains_.push_back(std::move(cs));
  }
  output_reads_.resize(chains_.size());
  for (std::size_t c = 0; c < chains_.size(); ++c) output_reads_[c].assign(chip_count(c), {kNever, kNever});
}

void Board::note_output_read(std::size_t chain, std::size_t chip, Pin pin) {
  if (chain >= output_reads_.size() || chip >= output_reads_[chain].size() || (pin != Pin::BUSY && pin != Pin::FLAG)) return;
  output_reads_[chain][chip][pin == Pin::FLAG ? 1 : 0] = time_.now();
  if (coverage_) {
    ChainState& c = state(chain);
    coverage_->output_read(chain, chip, c.chain.chip(chip), pin, level_of(c, chip, pin));
  }
}

void Board::note_output_edge(std::size_t chain, std::size_t chip, Pin pin, bool rising) {
  if (chain >= output_reads_.size() || chip >= output_reads_[chain].size() || (pin != Pin::BUSY && pin != Pin::FLAG)) return;
  output_reads_[chain][chip][pin == Pin::FLAG ? 1 : 0] = time_.now();
  if (coverage_) coverage_->output_edge(chain, chip, pin, rising);
}

// ---------------------------------------------------------------- coverage

void Board::enable_coverage() {
  if (coverage_) return;
  coverage_ = std::make_unique<CoverageCollector>();
  for (auto& c : chains_) {
    coverage_->add_chain(c->chain, numbering_);
    for (std::size_t k = 0; k < c->chain.size(); ++k) install_command_sink(*c, k);
    coverage_->look(c->index, c->chain);
  }
  sanitizer_.set_broken_sink([this](const Violation& v) {
    const int chain = find_chain(v.chain);
    if (chain < 0 || !coverage_) return;
    std::optional<std::size_t> chip;
    if (!v.chip_key.empty() && v.chip_key.find_first_not_of("0123456789") == std::string::npos)
      chip = static_cast<std::size_t>(std::stoull(v.chip_key));
    coverage_->rule_broken(static_cast<std::size_t>(chain), chip, v.rule);
  });
}

CoverageData Board::coverage() const {
  if (!coverage_) return {};
  for (const auto& c : chains_) coverage_->look(c->index, c->chain, true);  // the flags as the run ends
  return coverage_->data();
}

void Board::set_command_observer(std::size_t chain, std::size_t chip, Chip::CommandSink sink) {
  ChainState& c = state(chain);
  c.command_observers.at(chip) = std::move(sink);
  install_command_sink(c, chip);
}

void Board::install_command_sink(ChainState& c, std::size_t k) {
  // No sink at all when nobody listens: the chip then answers GetStatus polls from its cache.
  Chip::CommandSink* observer = c.command_observers[k] ? &c.command_observers[k] : nullptr;
  if (!observer && !coverage_) return c.chain.chip(k).set_command_sink({});
  c.chain.chip(k).set_command_sink([this, observer, chain = &c.chain, index = c.index, k](const Opcode& op, std::uint32_t arg) {
    if (coverage_) coverage_->command(index, k, chain->chip(k), op, arg);
    if (observer) (*observer)(op, arg);
  });
}

Tick Board::last_output_read(std::size_t chain, std::size_t chip, Pin pin) const {
  if (chain >= output_reads_.size() || chip >= output_reads_[chain].size() || (pin != Pin::BUSY && pin != Pin::FLAG)) return kNever;
  return output_reads_[chain][chip][pin == Pin::FLAG ? 1 : 0];
}

Board::~Board() = default;

Board::ChainState& Board::state(std::size_t chain) const { return *chains_.at(chain); }

// ---------------------------------------------------------------- chains

std::size_t Board::chip_count(std::size_t chain) const { return state(chain).chain.size(); }

const ChainConfig& Board::chain_config(std::size_t chain) const { return state(chain).config; }

const std::string& Board::chain_name(std::size_t chain) const { return state(chain).name; }

const Chain& Board::chain(std::size_t chain) const { return state(chain).chain; }

std::string Board::chain_summary(std::size_t chain) const {
  const ChainState& c = state(chain);
  std::ostringstream o;
  o << c.config.path << ": " << c.chain.size() << " chip" << (c.chain.size() == 1 ? "" : "s") << " (";
  o << chip_list_text(c.config.chips) << ")";
  return o.str();
}

int Board::find_chain(const std::string& name) const {
  for (std::size_t i = 0; i < chains_.size(); ++i) {
    const ChainState& c = *chains_[i];
    const std::string short_name = std::to_string(c.config.bus) + "." + std::to_string(c.config.cs);
    if (name == c.name || name == c.config.path || name == short_name) return static_cast<int>(i);
    if (c.config.gpiochip && name == "gpiochip" + std::to_string(*c.config.gpiochip)) return static_cast<int>(i);
  }
  return -1;
}

void Board::with_chain(std::size_t chain, const std::function<void(Chain&)>& f) {
  ChainState& c = state(chain);
  catch_up(c);
  c.prediction_valid = false;
  f(c.chain);
  if (c.recorder) c.recorder->outputs_may_have_changed();
  emit_changes(c, c.chain.now());
}

// ---------------------------------------------------------------- SPI

SpiDevice& Board::begin_transfer(std::size_t chain, const WireSettings& wire) {
  ChainState& c = state(chain);
  c.prediction_valid = false;
  // The use starts when the bus is free: now, or when the use before it on this bus ends.
  const Tick start = std::max(time_.now(), bus_free_[c.config.bus]);
  bring_to(c, start);
  record_outputs(c);
  c.touched = true;
  // One controller per bus: a chip-select still held low on another device of the bus is released first.
  for (auto& other : chains_)
    if (other.get() != &c && other->config.bus == c.config.bus && other->bus->selected()) {
      other->bus->set_device(spi_of(*other));
      other->bus->deselect_wire();
    }
  c.bus->set_device(spi_of(c));
  c.bus->begin(wire);
  return *c.bus;
}

Tick Board::end_transfer(std::size_t chain) {
  ChainState& c = state(chain);
  c.bus->end();
  if (!c.watched.empty())
    emit_changes(c, c.chain.now());
  else if (coverage_)
    coverage_->look(c.index, c.chain);
  return bus_free_[c.config.bus] = c.chain.now();
}

Tick Board::transfer(std::size_t chain, std::span<const SpiTransfer> transfers, const BusTiming& timing) {
  run_message(begin_transfer(chain, timing.wire), transfers, timing);
  return end_transfer(chain);
}

void Board::drive_chip_select(std::size_t chain, bool selected) {
  ChainState& c = state(chain);
  catch_up(c);
  c.prediction_valid = false;
  c.touched = true;
  // Through the chain's bus, as a host's CS edge: t_disCS (a CS low too soon after a rise
  // misses the chips' answer load) and the sanitizer's frame checks apply.
  c.bus->set_device(spi_of(c));
  if (selected) {
    c.bus->select_wire();
    if (c.chain.selected()) c.pin_bus.cs_fell(c.chain);
  } else if (c.chain.selected()) {
    spi_frame_ends(c);
    c.bus->deselect_wire();
  }
  emit_changes(c, c.chain.now());
}

void Board::spi_frame_ends(ChainState& c) {
  // A frame's own rule at the pins (SPI_PINS): clocks that stopped inside a byte. (A frame with
  // no clock at all is the front's to judge: a pin set to output low before it is driven high
  // makes one at every start.)
  const std::uint64_t whole = c.pin_bus.bytes_in_frame();
  if (const unsigned bits = c.pin_bus.cs_rising(); bits != 0)
    c.checker->spi_pins(whole, "the frame ended " + std::to_string(bits) + " bit" + (bits == 1 ? "" : "s") + " into byte " +
                                   std::to_string(whole) + ": the chips decode what the last whole byte left in their "
                                   "registers and the bits are lost");
}

void Board::drive_spi_clock(std::size_t chain, bool level) {
  ChainState& c = state(chain);
  PinLevelBus& pins = c.pin_bus;
  if (level == pins.ck()) return;
  const Tick now = time_.now();
  if (!pins.selected()) {
    pins.set_ck(level, *c.bus, c.chain);  // counted, nothing shifts
    return;
  }
  // Only the eighth rising edge of a byte reaches the chips; the others are the bus's own.
  const bool byte_ends = level && pins.bits_pending() == 7;
  if (byte_ends) {
    catch_up(c);
    c.prediction_valid = false;
    c.touched = true;
    record_outputs(c);
    c.bus->set_device(spi_of(c));
  }
  if (pins.set_ck(level, *c.bus, c.chain)) c.checker->first_clock_edge(now);
  if (byte_ends) emit_changes(c, c.chain.now());
}

void Board::drive_spi_data(std::size_t chain, bool level) { state(chain).pin_bus.set_sdi(level); }

std::optional<bool> Board::spi_data_out(std::size_t chain) const {
  const ChainState& c = state(chain);
  if (!c.pin_bus.selected()) return std::nullopt;
  return c.pin_bus.sdo(c.chain);
}

const PinLevelBus& Board::spi_pins(std::size_t chain) const { return state(chain).pin_bus; }

void Board::report_spi_pins(std::size_t chain, std::string what) { state(chain).checker->spi_pins(std::nullopt, std::move(what)); }

bool Board::chip_selected(std::size_t chain) const { return state(chain).chain.selected(); }

Tick Board::clock_bytes(std::span<const std::size_t> chains, std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx,
                        const BusSettings& settings) {
  Tick start = time_.now();
  for (const std::size_t i : chains) start = std::max(start, bus_free_[state(i).config.bus]);
  const Tick per_byte = transfer_ticks(1, settings.speed_hz);
  const Tick end = start + per_byte * tx.size();
  // The host's settings as the wire sees them: mode 3, MSB first takes the chain's byte path,
  // anything else the bit-level one (spi/wire.hpp). The front drives CS itself, so its ticks
  // are the real CS-to-clock time (t_setCS is checked).
  WireSettings wire;
  wire.mode = static_cast<std::uint8_t>(settings.mode & 3u);
  wire.lsb_first = settings.lsb_first;
  wire.speed_hz = settings.speed_hz;
  wire.bits_per_word = settings.bits_per_word;
  wire.cs_setup_timed = true;
  bool any = false;
  for (const std::size_t i : chains) {
    ChainState& c = state(i);
    if (!c.chain.selected()) continue;
    c.prediction_valid = false;
    c.touched = true;
    bring_to(c, start);
    record_outputs(c);
    ChainBus& bus = *c.bus;
    bus.set_device(spi_of(c));
    for (std::size_t k = 0; k < tx.size(); ++k) {
      bus.advance_to(bus.now() + per_byte);
      std::uint8_t in = 0;
      bus.exchange_wire(tx.subspan(k, 1), std::span<std::uint8_t>(&in, 1), wire);
      rx[k] = any ? static_cast<std::uint8_t>(rx[k] & in) : in;
    }
    any = true;
    emit_changes(c, c.chain.now());
    bus_free_[c.config.bus] = end;
  }
  if (!any) std::fill(rx.begin(), rx.begin() + static_cast<std::ptrdiff_t>(tx.size()), std::uint8_t{0});
  return end;
}

// ---------------------------------------------------------------- pins

bool Board::level_of(const ChainState& c, std::size_t chip, Pin pin) const {
  const Chip& ch = c.chain.chip(chip);
  if (pin == Pin::BUSY) return ch.busy_sync_pin();
  if (pin == Pin::FLAG) return ch.flag_pin();
  if (!variant_has_pin(ch.variant(), pin)) return true;  // an input the chip lacks: nothing pulls it low
  if (c.wired) return c.wire[chip][static_cast<unsigned>(pin)];
  if (pin == Pin::SW) return ch.sw_pin();
  if (pin == Pin::DIR) return ch.dir_pin();
  return pin == Pin::STBY_RST ? ch.spi_enabled() : false;
}

bool Board::level(std::size_t chain, std::size_t chip, Pin pin) const { return level_of(state(chain), chip, pin); }

bool Board::set_input(std::size_t chain, std::size_t chip, Pin pin, bool level) {
  if (chain >= chains_.size() || pin_is_chip_output(pin)) return false;
  ChainState& c = *chains_[chain];
  if (chip >= c.chain.size() || !variant_has_pin(c.chain.peek_chip(chip).variant(), pin)) return false;
  c.prediction_valid = false;
  if (c.wired) {
    bool& wire = c.wire[chip][static_cast<unsigned>(pin)];
    if (wire == level) return true;
    wire = level;
  }
  apply_input(c, chip, pin, level);
  return true;
}

bool Board::drive_pin(std::size_t chain, std::size_t chip, Pin pin, bool level) {
  if (chain >= chains_.size() || pin_is_chip_output(pin)) return false;
  ChainState& c = *chains_[chain];
  if (chip >= c.chain.size() || !variant_has_pin(c.chain.peek_chip(chip).variant(), pin)) return false;
  catch_up(c);
  set_input(chain, chip, pin, level);
  emit_changes(c, c.chain.now());
  return true;
}

bool Board::pin_level(std::size_t chain, std::size_t chip, Pin pin) {
  ChainState& c = state(chain);
  catch_up(c);
  return level_of(c, chip, pin);
}

void Board::watch_pin(std::size_t chain, std::size_t chip, Pin pin, bool watched) { set_watch(chain, chip, pin, watched, false); }

void Board::observe_pin(std::size_t chain, std::size_t chip, Pin pin, bool observed) {
  set_watch(chain, chip, pin, observed, true);
}

void Board::set_watch(std::size_t chain, std::size_t chip, Pin pin, bool on, bool observer) {
  ChainState& c = state(chain);
  c.prediction_valid = false;
  ChainState::WatchedPin w{chip, pin};
  auto it = std::lower_bound(c.watched.begin(), c.watched.end(), w);
  const bool found = it != c.watched.end() && it->same_pin(w);
  if (!on) {
    if (!found) return;
    (observer ? it->by_observer : it->by_front) = false;
    if (!it->by_front && !it->by_observer) c.watched.erase(it);
    return;
  }
  if (!found) it = c.watched.insert(it, w);
  (observer ? it->by_observer : it->by_front) = true;
  c.last.at(chip)[static_cast<unsigned>(pin)] = level_of(c, chip, pin);
}

bool Board::has_watched_pins(std::size_t chain) const {
  for (const ChainState::WatchedPin& w : state(chain).watched)
    if (w.by_front) return true;
  return false;
}

void Board::report_changes(std::size_t chain) {
  ChainState& c = state(chain);
  emit_changes(c, c.chain.now());
}

void Board::emit_changes(ChainState& c, Tick tick) {
  record_outputs(c);
  if (coverage_) coverage_->look(c.index, c.chain);
  for (const ChainState::WatchedPin& w : c.watched) {
    const bool level = level_of(c, w.chip, w.pin);
    bool& last = c.last[w.chip][static_cast<unsigned>(w.pin)];
    if (level == last) continue;
    last = level;
    const PinEdge edge{c.index, w.chip, w.pin, level, tick};
    if (w.by_front && edge_sink_) edge_sink_(edge);
    if (w.by_observer && observer_sink_) observer_sink_(edge);
  }
}

// ---------------------------------------------------------------- time and edges

void Board::catch_up(std::size_t chain) { catch_up(state(chain)); }

void Board::catch_up(ChainState& c) { bring_to(c, time_.now()); }

void Board::bring_to(ChainState& c, Tick target) {
  if (!c.trains.empty()) return run_trains(c, target);  // board_pulses.cpp
  if (target > c.chain.now()) advance_chain(c, target);
}

Tick Board::first_change(ChainState& c, std::size_t chip, Pin pin, bool level, Tick from, Tick to) {
  auto level_at = [&](Tick t) {
    Chip probe = c.chain.chip(chip);
    probe.set_diagnostic_sink({});
    probe.advance_to(t);
    return pin == Pin::BUSY ? probe.busy_sync_pin() : probe.flag_pin();
  };
  if (level_at(to) == level) return kNever;
  Tick lo = from, hi = to;  // level at lo is `level`, at hi it differs
  while (hi - lo > 1) {
    const Tick mid = lo + (hi - lo) / 2;
    if (level_at(mid) == level)
      lo = mid;
    else
      hi = mid;
  }
  return hi;
}

void Board::advance_chain(ChainState& c, Tick target) {
  // Collecting coverage: a look at every change of the motion's phase on the way, so that a
  // flag that rises and falls with time alone (MOT_STATUS constant speed inside a host's sleep)
  // counts as raised. Each chip's STATUS holds still through its run of uniform ticks.
  for (int phases = 0; coverage_ && phases < 64; ++phases) {
    Tick next = target;
    for (std::size_t k = 0; k < c.chain.size(); ++k) {
      const Chip& chip = c.chain.chip(k);
      if (!chip.spi_enabled()) continue;
      (void)chip.status();  // works the run out, so that the levels know how long they hold
      const Chip::OutputLevels o = chip.output_levels();
      if (o.active && o.steady_through >= c.chain.now() && o.steady_through + 1 < next) next = o.steady_through + 1;
    }
    if (next >= target) break;
    advance_chain_to(c, next);
    coverage_->look(c.index, c.chain, true);
  }
  advance_chain_to(c, target);
}

void Board::advance_chain_to(ChainState& c, Tick target) {
  // Through the recording when there is one: it records every BUSY and FLAG edge at its tick.
  SpiDevice& dev = spi_of(c);
  if (c.watched.empty() || (c.prediction_valid && target < c.predicted_edge)) {
    dev.advance_to(target);  // nothing watched changes before `target`
    return;
  }
  // Step from edge to edge so that every edge carries the tick it happened at.
  for (int guard = 0; guard < 10000 && c.chain.now() < target; ++guard) {
    Tick first = kNever;
    for (const ChainState::WatchedPin& w : c.watched) {
      if (!pin_is_chip_output(w.pin)) continue;
      if (c.chain.chip(w.chip).next_event_tick() == kNever) continue;  // nothing moves on its own
      first = std::min(first, first_change(c, w.chip, w.pin, c.last[w.chip][static_cast<unsigned>(w.pin)],
                                           c.chain.now(), target));
    }
    if (first == kNever) {
      dev.advance_to(target);
      break;
    }
    dev.advance_to(first);
    emit_changes(c, first);
  }
  if (c.chain.now() < target) dev.advance_to(target);
}

Tick Board::predict_next_edge(ChainState& c) {
  const Tick now = c.chain.now();
  if (c.prediction_valid && c.predicted_edge > now) return c.predicted_edge;
  Tick best = kNever;
  for (const ChainState::WatchedPin& w : c.watched) {
    if (!pin_is_chip_output(w.pin)) continue;
    if (c.chain.chip(w.chip).next_event_tick() == kNever) continue;
    // Exponential search forward, then bisection (first_change) inside the bracket.
    Tick lo = now;
    for (Tick step = 64; step < (Tick{1} << 40) && lo < best; step *= 2) {
      const Tick hi = now + step;
      const Tick t = first_change(c, w.chip, w.pin, c.last[w.chip][static_cast<unsigned>(w.pin)], lo, hi);
      if (t != kNever) {
        best = std::min(best, t);
        break;
      }
      lo = hi;
    }
  }
  c.prediction_valid = true;
  c.predicted_edge = best;
  return best;
}

bool Board::advance(Tick ticks) {
  if (!time_.is_virtual() || !advance_to(time_.now() + ticks)) return false;
  for (auto& c : chains_)
    if (c->recorder) {
      c->recorder->mark_advance();
      record_outputs(*c);
    }
  return true;
}

bool Board::advance_to(Tick tick) {
  if (!time_.is_virtual()) return false;
  const Tick target = time_.set_now(tick);
  for (auto& c : chains_) {
    bring_to(*c, target);
    emit_changes(*c, c->chain.now());
  }
  return true;
}

Tick Board::next_edge_tick() {
  Tick best = kNever;
  for (auto& c : chains_) {
    catch_up(*c);
    best = std::min(best, predict_next_edge(*c));
  }
  return best;
}

Tick Board::predict_edge_tick(std::size_t chain) { return predict_next_edge(state(chain)); }

Tick Board::now(std::size_t chain) {
  ChainState& c = state(chain);
  catch_up(c);
  return c.chain.now();
}

}  // namespace l6470emu
