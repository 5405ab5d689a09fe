// RecordingChain: forwards to the Chain and writes trace events at the CS rising edge.
#include "daisychain/recording_chain.hpp"

#include <algorithm>
#include <cstring>

#include "core/axis_text.hpp"
#include "daisychain/chain_spec.hpp"

namespace l6470emu {

RecordingChain::RecordingChain(Chain& chain, TraceSink& sink, RecordOptions options)
    : chain_(chain), sink_(sink), options_(options) {
  TraceHeader h;
  h.format = "native";
  h.chain = chain_spec_of(chain_);
  h.board = options_.board;
  sink_.write_header(h);
  if (options_.observe_outputs) {
    busy_.assign(chain_.size(), 2);  // 2 = not seen yet: the first look records the level
    flag_.assign(chain_.size(), 2);
    sw_.assign(chain_.size(), 2);
    observe_outputs();
  }
}

void RecordingChain::emit(const TraceEvent& e) { sink_.write(e); }

namespace {

/// How far ahead a recording looks for BUSY/FLAG changes when time passes (64 ms): nothing to
/// look at again until then, unless something is done to the chain.
constexpr Tick kLookAheadTicks = ticks_from_ms(64);

}  // namespace

/// The first tick in (now, to] at which `chip`'s BUSY, FLAG or axis-driven SW differs from its level now
/// (kNever: neither changes by then), found on copies of the chip moved on (cheap: a copy
/// keeps the chip's knowledge of the motion's uniform runs). `unsure` is set when a BUSY that
/// is the SYNC clock was left out.
Tick RecordingChain::first_output_change(std::size_t k, Tick to, bool& unsure) const {
  const Chip& chip = chain_.chip(k);
  const Tick from = chain_.now();
  if (!chip.spi_enabled()) return kNever;  // held in standby: BUSY high, nothing moves
  const bool sync = chip.sync_clock_on();
  unsure = unsure || sync;
  const bool busy0 = chip.busy_sync_pin(), flag0 = chip.flag_pin();
  const bool axis = chip.has_axis(), sw0 = chip.sw_pin();
  auto differs_at = [&](Tick t) {
    Chip probe = chip;
    probe.set_diagnostic_sink({});
    probe.advance_to(t);
    return (!sync && probe.busy_sync_pin() != busy0) || probe.flag_pin() != flag0 || (axis && probe.sw_pin() != sw0);
  };
  if (!differs_at(to)) return kNever;
  Tick lo = from, hi = to;  // the same at lo, different at hi
  while (hi - lo > 1) {
    const Tick mid = lo + (hi - lo) / 2;
    (differs_at(mid) ? hi : lo) = mid;
  }
  return hi;
}

void RecordingChain::advance_to(Tick tick) {
  if (!options_.observe_outputs || chain_.selected() || tick <= chain_.now()) {
    chain_.advance_to(tick);
    return;
  }
  if (observed_at_ != kNever && tick <= quiet_until_) {
    // The usual case, on every call of a polling host: the last look's levels hold up to
    // `tick` (what observe_outputs() and the loop below would find at once), in a function
    // small enough to save no registers.
    chain_.advance_to(tick);
    observed_at_ = tick;
    return;
  }
  advance_observing(tick);
}

[[gnu::noinline]] void RecordingChain::advance_observing(Tick tick) {
  observe_outputs();  // what is recorded is the levels now
  // Step from change to change so that each is recorded at the tick it happens. A look ahead
  // that finds nothing up to quiet_until_ holds until something is done to the chain.
  for (int guard = 0; guard < 10000 && chain_.now() < tick; ++guard) {
    if (tick <= quiet_until_) {
      chain_.advance_to(tick);
      observed_at_ = tick;  // nothing changed on the way
      return;
    }
    const Tick ahead = std::max(tick, chain_.now() + kLookAheadTicks);
    Tick first = kNever;
    bool unsure = false;
    for (std::size_t k = 0; k < chain_.size(); ++k) {
      if (chain_.chip(k).next_event_tick() == kNever) continue;  // nothing moves on its own
      first = std::min(first, first_output_change(k, ahead, unsure));
    }
    if (first == kNever || first > tick) {
      if (unsure) {  // a SYNC clock: looked at when the time comes, not stepped
        chain_.advance_to(tick);
        observe_outputs();
        return;
      }
      quiet_until_ = first == kNever ? ahead : first - 1;
      continue;
    }
    chain_.advance_to(first);
    observe_outputs();
  }
  chain_.advance_to(tick);
  observe_outputs();
}

void RecordingChain::select() {
  if (chain_.selected()) return;
  start_frame(false);
  chain_.select();
}

void RecordingChain::select_wire() {
  if (chain_.selected()) return;
  start_frame(true);
  chain_.select_wire();
}

void RecordingChain::start_frame(bool timed) {
  frame_start_ = chain_.now();
  decoded_at_select_ = chain_.decoded_bytes();
  frame_bytes_ = 0;
  frame_timed_ = timed;
  wire_noted_ = false;
}

namespace {

/// The wire of a frame clocked through the byte face: SPI mode 3, MSB first. Untimed, that is
/// how a trace that says nothing is replayed (no `wire` line); timed, it must be said.
TraceWire byte_face_wire(bool timed) {
  TraceWire w;
  w.known = timed;
  w.deselect_timed = timed;
  return w;
}

}  // namespace

std::uint8_t RecordingChain::exchange(std::uint8_t mosi) {
  if (!chain_.selected()) touched();  // a frame's bytes are judged when CS rises (finish_frame)
  const std::uint8_t miso = chain_.exchange(mosi);
  if (chain_.selected()) {
    note_wire(byte_face_wire(frame_timed_));
    keep({&mosi, 1}, {&miso, 1});
  }
  return miso;
}

inline void RecordingChain::keep(std::span<const std::uint8_t> tx, std::span<const std::uint8_t> rx) {
  // Into buffers that only ever grow. Most frames are a few bytes, clocked a byte at a time: a
  // plain loop here, inlined where the bytes come in; the rest out of line.
  const std::size_t at = frame_bytes_, n = tx.size();
  if (n > 16 || at + n > tx_.size()) [[unlikely]] {
    keep_long(tx, rx);
    return;
  }
  std::uint8_t* t = tx_.data() + at;
  std::uint8_t* r = rx_.data() + at;
  for (std::size_t i = 0; i < n; ++i) {
    t[i] = tx[i];
    r[i] = rx[i];
  }
  frame_bytes_ = at + n;
}

[[gnu::noinline]] void RecordingChain::keep_long(std::span<const std::uint8_t> tx, std::span<const std::uint8_t> rx) {
  const std::size_t at = frame_bytes_, n = tx.size();
  if (at + n > tx_.size()) {
    tx_.resize(std::max<std::size_t>(2 * (at + n), 64));
    rx_.resize(tx_.size());
  }
  std::memcpy(tx_.data() + at, tx.data(), n);
  std::memcpy(rx_.data() + at, rx.data(), n);
  frame_bytes_ = at + n;
}

void RecordingChain::exchange(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  if (!chain_.selected()) touched();
  chain_.exchange(tx, rx);
  if (chain_.selected()) {
    note_wire(byte_face_wire(frame_timed_));
    keep(tx, rx);
  }
}

void RecordingChain::exchange_wire(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx,
                                   const WireSettings& wire) {
  // (Clocking bytes never moves CS: selected before is selected after.)
  if (!chain_.selected()) [[unlikely]] {
    touched();
    chain_.exchange_wire(tx, rx, wire);
    return;
  }
  chain_.exchange_wire(tx, rx, wire);
  if (!wire_noted_) note_wire(trace_wire_of(wire, frame_timed_));
  keep(tx, rx);
}

void RecordingChain::deselect() {
  if (!chain_.selected()) {
    touched();
    return;
  }
  chain_.deselect();
  finish_frame();
}

void RecordingChain::deselect_wire() {
  if (!chain_.selected()) {
    touched();
    return;
  }
  chain_.deselect_wire();
  finish_frame();
}

void RecordingChain::finish_frame() {
  TraceEvent& e = frame_event_;  // a frame event with every other field at its default
  e.tick = frame_start_;
  e.duration = chain_.now() - frame_start_;
  e.mosi = {tx_.data(), frame_bytes_};
  // A frame of no bytes gets an empty MISO list (nothing to compare).
  e.miso = {rx_.data(), frame_bytes_};
  if (!wire_noted_ && wire_.deselect_timed != frame_timed_) {
    // No byte clocked: the settings stay the last frame's, the CS timing is this frame's.
    wire_.deselect_timed = frame_timed_;
    wire_.known = wire_.known || frame_timed_;
  }
  e.wire = wire_;
  emit(e);
  ++frames_;
  for (const TraceEvent& d : deferred_) emit(d);
  deferred_.clear();
  // Only a byte through a chip's decoder changes what the chip drives: a frame of NOPs, or of
  // GetStatus answered from the cached STATUS, leaves the last look standing (and, with every
  // chip idle at that look, the outputs are not looked at again).
  if (chain_.decoded_bytes() != decoded_at_select_) {
    touched();
  }
  observe_outputs();
}

void RecordingChain::backdoor(std::size_t chip, TraceEventKind kind, std::uint8_t what, std::uint8_t value) {
  TraceEvent e;
  e.kind = kind;
  e.tick = chain_.now();
  e.chip = static_cast<std::uint16_t>(chip);
  e.value = value;
  if (kind == TraceEventKind::pin)
    e.pin = static_cast<TracePin>(what);
  else
    e.fault = static_cast<TraceFault>(what);
  if (e.is_observation()) {
    emit(e);  // an observation, made between frames
    return;
  }
  stimulus(e);
}

void RecordingChain::stimulus(const TraceEvent& e) {
  touched();
  if (chain_.selected()) {
    deferred_.push_back(e);
    return;
  }
  emit(e);
  observe_outputs();
}

void RecordingChain::set_axis_load(std::size_t chip, const LoadSpec& load) {
  chain_.chip(chip).set_axis_load(load);
  TraceEvent e;
  e.kind = TraceEventKind::load;
  e.tick = chain_.now();
  e.chip = static_cast<std::uint16_t>(chip);
  e.load = load;
  stimulus(e);
}

void RecordingChain::axis_event(std::size_t chip, TraceEvent& e) {
  e.tick = chain_.now();
  e.chip = static_cast<std::uint16_t>(chip);
  stimulus(e);
}

void RecordingChain::attach_axis(std::size_t chip, const AxisSpec& spec) {
  chain_.chip(chip).attach_axis(spec);
  const std::string text = describe_axis_spec(spec);
  TraceEvent e;
  e.kind = TraceEventKind::axis;
  e.text = text.empty() ? std::string_view("default") : std::string_view(text);
  axis_event(chip, e);
}

void RecordingChain::detach_axis(std::size_t chip) {
  chain_.chip(chip).detach_axis();
  if (!sw_.empty()) sw_[chip] = 2;  // no axis drives it now
  TraceEvent e;
  e.kind = TraceEventKind::axis;
  e.text = "none";
  axis_event(chip, e);
}

void RecordingChain::set_axis_stops(std::size_t chip, bool has_lower, std::int64_t lower, bool has_upper,
                                    std::int64_t upper) {
  chain_.chip(chip).set_axis_stops(has_lower, lower, has_upper, upper);
  TraceEvent e;
  e.kind = TraceEventKind::stops;
  e.has_lower_stop = has_lower;
  e.lower_stop = has_lower ? lower : 0;
  e.has_upper_stop = has_upper;
  e.upper_stop = has_upper ? upper : 0;
  axis_event(chip, e);
}

void RecordingChain::set_axis_supply(std::size_t chip, std::uint32_t supply_mV) {
  chain_.chip(chip).set_axis_supply(supply_mV);
  TraceEvent e;
  e.kind = TraceEventKind::supply;
  e.supply_mV = supply_mV;
  axis_event(chip, e);
}

void RecordingChain::mark_advance() {
  TraceEvent e;
  e.kind = TraceEventKind::advance;
  e.tick = chain_.now();
  stimulus(e);
}

void RecordingChain::set_sw_pin(std::size_t chip, bool level) {
  Chip& c = chain_.chip(chip);
  c.set_sw_pin(level);
  // The host drove it: not an observation of what the axis does.
  if (c.has_axis() && !sw_.empty() && sw_[chip] != 2) sw_[chip] = c.sw_pin();
  backdoor(chip, TraceEventKind::pin, static_cast<std::uint8_t>(TracePin::SW), level);
}
void RecordingChain::set_stck_pin(std::size_t chip, bool level) {
  chain_.chip(chip).set_stck_pin(level);
  backdoor(chip, TraceEventKind::pin, static_cast<std::uint8_t>(TracePin::STCK), level);
}
void RecordingChain::set_dir_pin(std::size_t chip, bool level) {
  chain_.chip(chip).set_dir_pin(level);
  backdoor(chip, TraceEventKind::pin, static_cast<std::uint8_t>(TracePin::DIR), level);
}
void RecordingChain::set_stby_rst_pin(std::size_t chip, bool level) {
  chain_.chip(chip).set_stby_rst_pin(level);
  backdoor(chip, TraceEventKind::pin, static_cast<std::uint8_t>(TracePin::STBY), level);
}
void RecordingChain::set_adc_input(std::size_t chip, std::uint8_t code) {
  chain_.chip(chip).set_adc_input(code);
  backdoor(chip, TraceEventKind::fault, static_cast<std::uint8_t>(TraceFault::ADCIN), code > 31 ? 31 : code);
}
void RecordingChain::set_undervoltage(std::size_t chip, bool active) {
  chain_.chip(chip).set_undervoltage(active);
  backdoor(chip, TraceEventKind::fault, static_cast<std::uint8_t>(TraceFault::UVLO), active);
}
void RecordingChain::set_adc_undervoltage(std::size_t chip, bool active) {
  chain_.chip(chip).set_adc_undervoltage(active);
  backdoor(chip, TraceEventKind::fault, static_cast<std::uint8_t>(TraceFault::UVLO_ADC), active);
}
void RecordingChain::set_thermal(std::size_t chip, Thermal t) {
  chain_.chip(chip).set_thermal(t);
  backdoor(chip, TraceEventKind::fault, static_cast<std::uint8_t>(TraceFault::THERMAL), static_cast<std::uint8_t>(t));
}
void RecordingChain::set_overcurrent(std::size_t chip, bool active) {
  chain_.chip(chip).set_overcurrent(active);
  backdoor(chip, TraceEventKind::fault, static_cast<std::uint8_t>(TraceFault::OCD), active);
}
void RecordingChain::set_stall(std::size_t chip, Bridge bridge, bool active) {
  chain_.chip(chip).set_stall(bridge, active);
  backdoor(chip, TraceEventKind::fault,
           static_cast<std::uint8_t>(bridge == Bridge::A ? TraceFault::STALL_A : TraceFault::STALL_B), active);
}

void RecordingChain::power_cycle(std::size_t chip) {
  chain_.power_cycle(chip);
  backdoor(chip, TraceEventKind::fault, static_cast<std::uint8_t>(TraceFault::POWER_CYCLE), 0);
}
void RecordingChain::miso_flip(std::size_t chip, std::uint8_t bit) {
  // Armed for the frame after any under way, as a replay arms it after this frame's line.
  chain_.arm_miso_flip(chip, bit & 7u);
  backdoor(chip, TraceEventKind::fault, static_cast<std::uint8_t>(TraceFault::MISO_FLIP), bit & 7u);
}
void RecordingChain::lost_frame(std::size_t chip) {
  chain_.arm_lost_frame(chip);
  backdoor(chip, TraceEventKind::fault, static_cast<std::uint8_t>(TraceFault::LOST_FRAME), 0);
}

// observe_outputs() comes here unless nothing can have changed since the last look: the same
// tick, or a look that found every chip with nothing to do on its own and no touch since.
void RecordingChain::look_at_outputs() {
  observed_at_ = chain_.now();
  bool idle = true;
  Tick steady = kNever;
  for (std::size_t k = 0; k < chain_.size(); ++k) {
    const Chip& c = chain_.chip(k);
    const Chip::OutputLevels levels = c.output_levels();
    idle = idle && !levels.active;
    steady = std::min(steady, levels.steady_through);
    if (c.has_axis() && levels.sw != sw_[k]) {
      sw_[k] = levels.sw;
      backdoor(k, TraceEventKind::pin, static_cast<std::uint8_t>(TracePin::SW_AXIS), levels.sw);
    }
    const std::uint8_t busy = levels.busy, flag = levels.flag;
    if (busy != busy_[k] && c.variant().pins.busy_sync) {  // an L6474 has no BUSY pin to observe
      busy_[k] = busy;
      backdoor(k, TraceEventKind::pin, static_cast<std::uint8_t>(TracePin::BUSY), busy);
    }
    if (flag != flag_[k]) {
      flag_[k] = flag;
      backdoor(k, TraceEventKind::pin, static_cast<std::uint8_t>(TracePin::FLAG), flag);
    }
  }
  idle_ = idle;
  quiet_until_ = std::max(quiet_until_, steady);
}

}  // namespace l6470emu
