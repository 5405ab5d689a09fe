// ScenarioRunner: the steps of a scenario fired at their ticks and events, actions through the
// Board's backdoor, expectations judged against the chips without side effects.
#include "board/scenario_runner.hpp"

#include <algorithm>
#include <stdexcept>

#include "board/board_config.hpp"
#include "core/commands.hpp"
#include "core/registers.hpp"
#include "core/variant.hpp"

namespace l6470emu {
namespace {

// The L6470's supply thresholds (VSthOff 7.2 V, VSthOn 8.2 V typical): a supply action below
// the first raises UVLO, one at or above the second clears it.
constexpr std::uint32_t kUvloOff_mV = 7'200;
constexpr std::uint32_t kUvloOn_mV = 8'200;

int sign_of(std::int64_t v) { return v < 0 ? -1 : v > 0 ? 1 : 0; }

const RegisterInfo* find_register(const Chip& chip, std::string_view name) {
  for (const RegisterInfo& r : chip.registers().registers)
    if (same_name(r.name, name)) return &r;
  return nullptr;
}

// STATUS bit of flag `name` in `layout`, or -1.
int status_bit(const StatusLayout& l, std::string_view name) {
  struct Named {
    std::string_view name;
    std::int8_t bit;
  };
  const Named table[] = {{"HiZ", l.hiz},           {"BUSY", l.busy},           {"SW_F", l.sw_f},
                         {"SW_EVN", l.sw_evn},     {"DIR", l.dir},             {"NOTPERF_CMD", l.notperf_cmd},
                         {"CMD_ERROR", l.notperf_cmd}, {"WRONG_CMD", l.wrong_cmd}, {"UVLO", l.uvlo},
                         {"UVLO_ADC", l.uvlo_adc}, {"TH_WRN", l.th_wrn},       {"TH_SD", l.th_sd},
                         {"OCD", l.ocd},           {l.step_loss_a_name, l.step_loss_a},
                         {l.step_loss_b_name, l.step_loss_b}, {"STEP_LOSS_A", l.step_loss_a},
                         {"STEP_LOSS_B", l.step_loss_b}, {"SCK_MOD", l.sck_mod}, {"STCK_MOD", l.sck_mod}};
  for (const Named& n : table)
    if (same_name(n.name, name)) return n.bit;
  return -1;
}

bool is_command_name(std::string_view name) {
  for (unsigned c = 0; c < static_cast<unsigned>(Command::Unknown); ++c)
    if (same_name(to_string(static_cast<Command>(c)), name)) return true;
  return false;
}

// Text as a scenario log shows it: in double quotes, control bytes and quotes escaped.
std::string shown_serial_text(std::string_view text) {
  std::string out = "\"";
  for (const char ch : text.substr(0, 200)) {
    const auto c = static_cast<unsigned char>(ch);
    if (ch == '\n') out += "\\n";
    else if (ch == '\r') out += "\\r";
    else if (ch == '"' || ch == '\\') out += std::string("\\") + ch;
    else if (c < 0x20 || c == 0x7f) {
      static const char* digits = "0123456789abcdef";
      out += std::string("\\x") + digits[c >> 4] + digits[c & 15];
    } else {
      out += ch;
    }
  }
  return out + (text.size() > 200 ? "\"..." : "\"");
}

std::string with_tolerance(std::int64_t v, std::int64_t tol) {
  return tol ? std::to_string(v) + " ± " + std::to_string(tol) : std::to_string(v);
}

// What an action does, in words ("SW closed", "OCD on", "hard stop at 12800").
std::string describe(const ScenarioAction& a) {
  switch (a.kind) {
    case ScenarioAction::Kind::sw: return a.level ? "SW opened" : "SW closed";
    case ScenarioAction::Kind::stby_rst: return a.level ? "STBY_RST high" : "STBY_RST low";
    case ScenarioAction::Kind::dir: return a.level ? "DIR high (forward)" : "DIR low (reverse)";
    case ScenarioAction::Kind::fault:
      if (a.fault == TraceFault::THERMAL) return "THERMAL " + std::string(thermal_name(a.value));
      if (a.fault == TraceFault::ADCIN) return "ADCIN " + std::to_string(a.value);
      if (a.fault == TraceFault::POWER_CYCLE) return "power cycle (reset)";
      if (a.fault == TraceFault::MISO_FLIP) return "MISO flip of bit " + std::to_string(a.value & 7u) + " in the next frame";
      if (a.fault == TraceFault::LOST_FRAME) return "next frame lost";
      return std::string(to_string(a.fault)) + (a.value ? " on" : " off");
    case ScenarioAction::Kind::load:
      return "load: inertia " + std::to_string(a.load.inertia_g_mm2) + " g·mm², friction " +
             std::to_string(a.load.friction_uNm) + " µN·m, force " + std::to_string(a.load.force_uNm) + " µN·m";
    case ScenarioAction::Kind::block: return "hard stop at " + std::to_string(a.position) + " (1/128 step)";
    case ScenarioAction::Kind::supply: return "supply " + std::to_string(a.supply_mV) + " mV";
    case ScenarioAction::Kind::serial: return "typed " + shown_serial_text(a.text);
  }
  return "";
}

bool is_event(ScenarioTrigger::Kind k) {
  return k != ScenarioTrigger::Kind::time && k != ScenarioTrigger::Kind::end;
}
bool is_position(ScenarioTrigger::Kind k) {
  return k == ScenarioTrigger::Kind::position || k == ScenarioTrigger::Kind::true_position;
}

}  // namespace

ScenarioRunner::ScenarioRunner(Board& board, Scenario scenario, SerialInput serial_input)
    : board_(board), scenario_(std::move(scenario)), serial_input_(std::move(serial_input)),
      state_(scenario_.steps.size()) {
  pulses_.resize(board_.chain_count());
  commands_.resize(board_.chain_count());
  uvlo_by_supply_.resize(board_.chain_count());
  for (std::size_t c = 0; c < board_.chain_count(); ++c) {
    pulses_[c].resize(board_.chip_count(c));
    commands_[c].resize(board_.chip_count(c));
    uvlo_by_supply_[c].assign(board_.chip_count(c), false);
  }
  std::vector<std::pair<std::size_t, std::size_t>> busy_watch;
  for (std::size_t i = 0; i < scenario_.steps.size(); ++i) check_step_against_board(i, busy_watch);
  for (std::size_t c = 0; c < board_.chain_count(); ++c)
    for (std::size_t k = 0; k < board_.chip_count(c); ++k)
      board_.set_command_observer(c, k, [this, c, k](const Opcode& op, std::uint32_t) {
        seen_.push_back(Seen{c, k, false, false, std::string(to_string(op.command)), board_.chain(c).chip(k).now()});
      });
  std::sort(busy_watch.begin(), busy_watch.end());
  busy_watch.erase(std::unique(busy_watch.begin(), busy_watch.end()), busy_watch.end());
  board_.set_observer_sink([this](const PinEdge& e) {
    if (e.pin == Pin::BUSY) seen_.push_back(Seen{e.chain, e.chip, true, e.level, {}, e.tick});
  });
  for (const auto& [c, k] : busy_watch) {
    board_.observe_pin(c, k, Pin::BUSY, true);
    if (!board_.pin_level(c, k, Pin::BUSY)) pulses_[c][k].push_back(Pulse{board_.now(c), kNever});
  }
  fire_due_times(board_.time().now());
}

void ScenarioRunner::check_step_against_board(std::size_t i, std::vector<std::pair<std::size_t, std::size_t>>& busy_watch) {
  const ScenarioStep& st = scenario_.steps[i];
  StepState& s = state_[i];
  const std::string& w = st.where;
  auto bad = [&](const std::string& what) { throw std::invalid_argument(w + ": " + what); };
  if (is_event(st.when.kind)) s.trigger_chip = resolve(st.when.chip, w);
  const Chip* tchip = is_event(st.when.kind) ? &board_.chain(s.trigger_chip.chain).chip(s.trigger_chip.chip) : nullptr;
  if (st.when.kind == ScenarioTrigger::Kind::true_position && !tchip->axis())
    bad(s.trigger_chip.label + " has no axis (axis.K= in the board description) for true_position");
  if (st.when.kind == ScenarioTrigger::Kind::command && !is_command_name(st.when.command))
    bad(quoted_text(st.when.command) + " is not a command (datasheet names: GoUntil, Move, GetStatus, ...)");
  if (st.when.kind == ScenarioTrigger::Kind::busy_fall || st.when.kind == ScenarioTrigger::Kind::busy_rise)
    busy_watch.emplace_back(s.trigger_chip.chain, s.trigger_chip.chip);
  if (st.action && st.action->kind == ScenarioAction::Kind::serial) {
    s.target_chip.label = "Serial";  // the program's, not a chip's
    if (st.when.kind == ScenarioTrigger::Kind::end) bad("an action cannot happen at the end");
  } else if (st.action) {
    const ScenarioAction& a = *st.action;
    s.target_chip = resolve(a.chip, w);
    const Chip& chip = board_.chain(s.target_chip.chain).chip(s.target_chip.chip);
    if (a.kind == ScenarioAction::Kind::dir && !variant_has_pin(chip.variant(), Pin::DIR))
      bad(s.target_chip.label + " (" + std::string(chip.variant().name) + ") has no DIR pin for dir: (an L6474 has)");
    if ((a.kind == ScenarioAction::Kind::load || a.kind == ScenarioAction::Kind::block) && !chip.axis())
      bad(s.target_chip.label + " has no axis (axis.K= in the board description) for " +
          std::string(to_string(a.kind)));
    if (st.when.kind == ScenarioTrigger::Kind::end) bad("an action cannot happen at the end");
  }
  if (st.expect) {
    const ScenarioExpectation& e = *st.expect;
    s.target_chip = resolve(e.chip, w);
    const Chip& chip = board_.chain(s.target_chip.chain).chip(s.target_chip.chip);
    if (e.kind == ScenarioExpectation::Kind::reg && !find_register(chip, e.name))
      bad("the " + std::string(chip.variant().name) + " has no register " + quoted_text(e.name));
    if (e.kind == ScenarioExpectation::Kind::true_position && !chip.axis())
      bad(s.target_chip.label + " has no axis (axis.K= in the board description) for true_position");
    if (e.kind == ScenarioExpectation::Kind::status)
      for (const auto& [name, bit] : e.flags)
        if (status_bit(chip.status_layout(), name) < 0)
          bad("the " + std::string(chip.variant().name) + "'s STATUS has no flag " + quoted_text(name));
    if (e.kind == ScenarioExpectation::Kind::command && !is_command_name(e.name))
      bad(quoted_text(e.name) + " is not a command (datasheet names: GoUntil, Move, GetStatus, ...)");
    if (e.kind == ScenarioExpectation::Kind::busy_pulse) {
      if (st.when.kind != ScenarioTrigger::Kind::end) bad("a BUSY pulse is judged at the end (at: end)");
      busy_watch.emplace_back(s.target_chip.chain, s.target_chip.chip);
    }
  }
}

void ScenarioRunner::add_steps(const std::vector<ScenarioStep>& steps) {
  for (const ScenarioStep& st : steps)
    if (st.when.kind != ScenarioTrigger::Kind::time && st.when.kind != ScenarioTrigger::Kind::end)
      throw std::invalid_argument(st.where + ": only a step at a time or at the end can join a running scenario");
  const std::size_t first = scenario_.steps.size();
  scenario_.steps.insert(scenario_.steps.end(), steps.begin(), steps.end());
  state_.resize(scenario_.steps.size());
  std::vector<std::pair<std::size_t, std::size_t>> busy_watch;
  try {
    for (std::size_t i = first; i < scenario_.steps.size(); ++i) check_step_against_board(i, busy_watch);
  } catch (...) {
    scenario_.steps.resize(first);
    state_.resize(first);
    throw;
  }
  fire_due_times(board_.time().now());
}

ScenarioRunner::~ScenarioRunner() {
  board_.set_observer_sink({});
  for (std::size_t c = 0; c < board_.chain_count(); ++c)
    for (std::size_t k = 0; k < board_.chip_count(c); ++k) {
      board_.observe_pin(c, k, Pin::BUSY, false);
      board_.set_command_observer(c, k, {});
    }
}

ScenarioRunner::Resolved ScenarioRunner::resolve(const ScenarioChip& c, const std::string& where) const {
  if (board_.chain_count() == 0) throw std::invalid_argument(where + ": the board has no chain");
  int chain = 0;
  if (!c.chain.empty()) {
    chain = board_.find_chain(c.chain);
    if (chain < 0) {
      std::string names;
      for (std::size_t i = 0; i < board_.chain_count(); ++i) names += (i ? ", " : "") + board_.chain_name(i);
      throw std::invalid_argument(where + ": no chain " + quoted_text(c.chain) + " on the board (it has " + names + ")");
    }
  }
  const std::size_t n = board_.chip_count(static_cast<std::size_t>(chain));
  if (c.number >= n)
    throw std::invalid_argument(where + ": no chip " + std::to_string(c.number) + " on " +
                                board_.chain_name(static_cast<std::size_t>(chain)) + " (chips 0.." +
                                std::to_string(n - 1) + ", " + describe_numbering(board_.numbering()) + ")");
  Resolved r;
  r.chain = static_cast<std::size_t>(chain);
  r.chip = board_.chip_numbering(r.chain).index_of(c.number);
  r.label = board_.chain_name(r.chain) + " chip " + std::to_string(c.number);
  return r;
}

Tick ScenarioRunner::next_tick() const {
  Tick t = kNever;
  for (std::size_t i = 0; i < state_.size(); ++i) {
    if (state_[i].done) continue;
    const ScenarioTrigger& w = scenario_.steps[i].when;
    if (w.kind == ScenarioTrigger::Kind::time) t = std::min(t, w.tick);
    // A position trigger is armed at its `not before` tick: the host must wake then too.
    if (is_position(w.kind) && !state_[i].armed) t = std::min(t, w.tick);
    t = std::min(t, state_[i].due);
  }
  return t;
}

bool ScenarioRunner::pending_events() const {
  for (std::size_t i = 0; i < state_.size(); ++i) {
    const auto k = scenario_.steps[i].when.kind;
    if (!state_[i].done && state_[i].due == kNever &&
        (k == ScenarioTrigger::Kind::busy_fall || k == ScenarioTrigger::Kind::busy_rise))
      return true;
  }
  return false;
}

bool ScenarioRunner::pending_positions() const {
  for (std::size_t i = 0; i < state_.size(); ++i)
    if (!state_[i].done && state_[i].due == kNever && is_position(scenario_.steps[i].when.kind)) return true;
  return false;
}

std::int64_t ScenarioRunner::position_of(const Chip& chip, bool true_position) const {
  if (true_position && chip.axis()) return chip.axis()->true_position();
  return chip.position();
}

Tick ScenarioRunner::position_reached_within(std::size_t i, Tick from, Tick to) {
  const ScenarioTrigger& w = scenario_.steps[i].when;
  const StepState& s = state_[i];
  if (!s.armed) return w.tick > from && w.tick <= to ? w.tick : kNever;
  const bool true_pos = w.kind == ScenarioTrigger::Kind::true_position;
  const Chip& base = board_.chain(s.trigger_chip.chain).chip(s.trigger_chip.chip);
  if (base.next_event_tick() == kNever) return kNever;  // nothing moves by itself
  auto reached_at = [&](Tick t) {
    Chip probe = base;
    probe.set_diagnostic_sink({});
    probe.set_command_sink({});
    probe.advance_to(t);
    const int side = sign_of(position_of(probe, true_pos) - w.position);
    return side == 0 || side != s.start_side;
  };
  if (!reached_at(to)) return kNever;
  Tick lo = std::max(from, base.now()), hi = to;
  if (lo >= hi) return hi;
  while (hi - lo > 1) {
    const Tick mid = lo + (hi - lo) / 2;
    if (reached_at(mid))
      hi = mid;
    else
      lo = mid;
  }
  return hi;
}

void ScenarioRunner::advance_to(Tick target) {
  for (int guard = 0; guard < 1'000'000; ++guard) {
    const Tick now = board_.time().now();
    fire_due_times(now);
    take_events(now);
    fire_positions(now);
    if (now >= target) break;
    Tick t = std::min(target, next_tick());
    if (pending_events()) t = std::min(t, board_.next_edge_tick());
    if (pending_positions())
      for (std::size_t i = 0; i < state_.size(); ++i)
        if (!state_[i].done && state_[i].due == kNever && is_position(scenario_.steps[i].when.kind))
          t = std::min(t, position_reached_within(i, now, t));
    t = std::max(t, now + 1);
    board_.advance_to(t);
  }
  board_.advance_to(target);
}

void ScenarioRunner::after_transfer() {
  const Tick now = board_.time().now();
  take_events(now);
  fire_due_times(now);
}

void ScenarioRunner::poll() {
  const Tick now = board_.time().now();
  for (std::size_t c = 0; c < board_.chain_count(); ++c) board_.catch_up(c);
  fire_due_times(now);
  take_events(now);
  fire_positions(now);
}

void ScenarioRunner::fire_due_times(Tick now) {
  for (std::size_t i = 0; i < state_.size(); ++i) {
    StepState& s = state_[i];
    const ScenarioTrigger& w = scenario_.steps[i].when;
    if (s.done) continue;
    if (w.kind == ScenarioTrigger::Kind::time && w.tick <= now) fire(i, w.tick);
    else if (s.due <= now) fire(i, s.due);
  }
}

void ScenarioRunner::fire_positions(Tick now) {
  for (std::size_t i = 0; i < state_.size(); ++i) {
    StepState& s = state_[i];
    const ScenarioTrigger& w = scenario_.steps[i].when;
    if (s.done || s.due != kNever || !is_position(w.kind) || w.tick > now) continue;
    const Chip& chip = board_.chain(s.trigger_chip.chain).chip(s.trigger_chip.chip);
    const int side = sign_of(position_of(chip, w.kind == ScenarioTrigger::Kind::true_position) - w.position);
    if (!s.armed) {
      s.armed = true;
      s.start_side = side;
    }
    if (side == 0 || side != s.start_side) triggered(i, std::max(now, chip.now()));
  }
}

void ScenarioRunner::take_events(Tick) {
  for (std::size_t n = 0; n < seen_.size(); ++n) {
    const Seen ev = seen_[n];  // a copy: firing may add to seen_
    if (ev.busy_edge) {
      auto& p = pulses_[ev.chain][ev.chip];
      if (!ev.level)
        p.push_back(Pulse{ev.tick, kNever});
      else if (!p.empty() && p.back().end == kNever)
        p.back().end = ev.tick;
    } else {
      auto& counts = commands_[ev.chain][ev.chip];
      auto it = std::find_if(counts.begin(), counts.end(), [&](const auto& e) { return e.first == ev.command; });
      if (it == counts.end())
        counts.emplace_back(ev.command, 1);
      else
        ++it->second;
    }
    for (std::size_t i = 0; i < state_.size(); ++i) {
      StepState& s = state_[i];
      const ScenarioTrigger& w = scenario_.steps[i].when;
      if (s.done || s.due != kNever || !is_event(w.kind) || is_position(w.kind) || ev.tick < w.tick) continue;
      if (s.trigger_chip.chain != ev.chain || s.trigger_chip.chip != ev.chip) continue;
      bool match = false;
      if (ev.busy_edge)
        match = (w.kind == ScenarioTrigger::Kind::busy_fall && !ev.level) ||
                (w.kind == ScenarioTrigger::Kind::busy_rise && ev.level);
      else
        match = w.kind == ScenarioTrigger::Kind::command && same_name(w.command, ev.command);
      if (match && ++s.seen >= w.count) triggered(i, ev.tick);
    }
  }
  seen_.clear();
}

void ScenarioRunner::triggered(std::size_t i, Tick tick) {
  const Tick delay = scenario_.steps[i].when.delay;
  if (delay == 0) {
    fire(i, tick);
    return;
  }
  state_[i].due = tick + delay;
  if (state_[i].due <= board_.time().now()) fire(i, state_[i].due);
}

void ScenarioRunner::fire(std::size_t i, Tick tick) {
  StepState& s = state_[i];
  s.done = true;
  const ScenarioStep& st = scenario_.steps[i];
  if (st.action && st.action->kind == ScenarioAction::Kind::serial && !serial_input_) {
    ++judged_;  // counted with the expectations: it is what fails the run
    fail(st.where, "serial input", tick, s.target_chip, "a program whose Serial reads it (a firmware sketch)",
         "a program with no Serial (under the preload): " + shown_serial_text(st.action->text) + " went nowhere");
  } else if (st.action) {
    log_.push_back(seconds_text(tick) + ": " + st.where + ": " + s.target_chip.label + ": " + describe(*st.action));
    apply(*st.action, s.target_chip, st.where);
  }
  if (st.expect) judge(*st.expect, s.target_chip, st.where, tick);
}

void ScenarioRunner::apply(const ScenarioAction& a, const Resolved& r, const std::string&) {
  switch (a.kind) {
    case ScenarioAction::Kind::sw:
      board_.drive_pin(r.chain, r.chip, Pin::SW, a.level);
      return;
    case ScenarioAction::Kind::stby_rst:
      board_.drive_pin(r.chain, r.chip, Pin::STBY_RST, a.level);
      return;
    case ScenarioAction::Kind::dir:
      board_.drive_pin(r.chain, r.chip, Pin::DIR, a.level);
      return;
    case ScenarioAction::Kind::fault:
      board_.inject_fault(r.chain, r.chip, a.fault, a.value);
      return;
    case ScenarioAction::Kind::load:
      board_.set_axis_load(r.chain, r.chip, a.load);  // recorded as a load event: replays with it
      return;
    case ScenarioAction::Kind::block: {
      // A stop on the side of the rotor the position is on; recorded as a stops event.
      bool has_axis = false, above = false;
      AxisSpec spec;
      board_.with_chain(r.chain, [&](Chain& c) {
        const Axis* axis = c.chip(r.chip).axis();
        if (!axis) return;
        has_axis = true;
        spec = axis->spec();
        above = axis->true_position() <= a.position;
      });
      if (!has_axis) return;
      if (above)
        board_.set_axis_stops(r.chain, r.chip, spec.has_lower_stop, spec.lower_stop, true, a.position);
      else
        board_.set_axis_stops(r.chain, r.chip, true, a.position, spec.has_upper_stop, spec.upper_stop);
      return;
    }
    case ScenarioAction::Kind::serial:
      serial_input_(a.text);
      return;
    case ScenarioAction::Kind::supply: {
      board_.set_axis_supply(r.chain, r.chip, a.supply_mV);  // recorded; no effect without an axis
      auto uvlo = uvlo_by_supply_[r.chain][r.chip];
      if (a.supply_mV < kUvloOff_mV && !uvlo) {
        board_.inject_fault(r.chain, r.chip, TraceFault::UVLO, 1);
        uvlo_by_supply_[r.chain][r.chip] = true;
      } else if (a.supply_mV >= kUvloOn_mV && uvlo) {
        board_.inject_fault(r.chain, r.chip, TraceFault::UVLO, 0);
        uvlo_by_supply_[r.chain][r.chip] = false;
      }
      return;
    }
  }
}

void ScenarioRunner::fail(const std::string& where, const std::string& what, Tick tick, const Resolved& r,
                          std::string expected, std::string seen) {
  failures_.push_back(ScenarioFailure{where, what, tick, r.label, std::move(expected), std::move(seen)});
  const ScenarioFailure& f = failures_.back();
  log_.push_back(seconds_text(tick) + ": " + where + ": " + r.label + ": " + what + " FAILED: expected " + f.expected +
                 ", seen " + f.seen);
}

void ScenarioRunner::pass(const std::string& where, const std::string& what) { passed_.push_back(where + ": " + what); }

void ScenarioRunner::judge(const ScenarioExpectation& e, const Resolved& r, const std::string& where, Tick tick) {
  ++judged_;
  board_.now(r.chain);  // the chain brought up to the clock
  const Chip& chip = board_.chain(r.chain).chip(r.chip);
  switch (e.kind) {
    case ScenarioExpectation::Kind::reg: {
      const RegisterInfo* reg = find_register(chip, e.name);
      const std::uint32_t raw = chip.peek(reg->id) & reg->mask();
      const std::int64_t v = reg->is_signed() ? sign_extend(raw, reg->bits) : std::int64_t{raw};
      const std::string what = std::string(reg->name);
      if (v < e.value - e.tolerance || v > e.value + e.tolerance)
        fail(where, what, tick, r, with_tolerance(e.value, e.tolerance), std::to_string(v));
      else
        pass(where, what + " = " + std::to_string(v));
      return;
    }
    case ScenarioExpectation::Kind::true_position: {
      const std::int64_t v = chip.axis()->true_position();
      if (v < e.value - e.tolerance || v > e.value + e.tolerance)
        fail(where, "true position (1/128 step)", tick, r, with_tolerance(e.value, e.tolerance), std::to_string(v));
      else
        pass(where, "true position = " + std::to_string(v));
      return;
    }
    case ScenarioExpectation::Kind::status: {
      const std::uint16_t status = chip.status();
      std::string expected, seen;
      bool ok = true;
      for (const auto& [name, bit] : e.flags) {
        const bool is = (status >> status_bit(chip.status_layout(), name)) & 1u;
        expected += (expected.empty() ? "" : " ") + name + "=" + (bit ? "1" : "0");
        seen += (seen.empty() ? "" : " ") + name + "=" + (is ? "1" : "0");
        ok = ok && is == bit;
      }
      char hex[16];
      std::snprintf(hex, sizeof hex, "0x%04X", status);
      if (!ok)
        fail(where, "STATUS", tick, r, expected, seen + " (STATUS " + hex + ")");
      else
        pass(where, "STATUS " + expected);
      return;
    }
    case ScenarioExpectation::Kind::busy_pulse: {
      const auto& pulses = pulses_[r.chain][r.chip];
      auto range = [&] {
        return seconds_text(e.min_ticks) + " .. " + (e.max_ticks == kNever ? std::string("any") : seconds_text(e.max_ticks));
      };
      if (e.pulse > pulses.size() || pulses.empty()) {
        fail(where, e.pulse ? "BUSY pulse " + std::to_string(e.pulse) : std::string("BUSY pulses"), tick, r,
             "a pulse of " + range(), std::to_string(pulses.size()) + " pulse" + (pulses.size() == 1 ? "" : "s"));
        return;
      }
      bool ok = true;
      for (std::size_t n = 0; n < pulses.size(); ++n) {
        if (e.pulse && n + 1 != e.pulse) continue;
        const Pulse& p = pulses[n];
        const Tick len = p.end == kNever ? kNever : p.end - p.start;
        if (len < e.min_ticks || len > e.max_ticks) {
          ok = false;
          fail(where, "BUSY pulse " + std::to_string(n + 1) + " (from " + seconds_text(p.start) + ")", tick, r, range(),
               len == kNever ? std::string("still low at the end") : seconds_text(len));
        }
      }
      if (ok) pass(where, "BUSY pulse" + std::string(e.pulse ? " " + std::to_string(e.pulse) : "s") + " within " + range());
      return;
    }
    case ScenarioExpectation::Kind::command: {
      std::uint64_t n = 0;
      for (const auto& [name, count] : commands_[r.chain][r.chip])
        if (same_name(name, e.name)) n += count;
      const bool ok = e.count == ScenarioExpectation::kAtLeastOnce ? n > 0 : n == e.count;
      const std::string expected = e.count == ScenarioExpectation::kAtLeastOnce ? std::string("sent")
                                   : e.count == 0                                ? std::string("not sent")
                                                                                 : e.count == 1 ? std::string("sent once") : "sent " + std::to_string(e.count) + " times";
      if (!ok)
        fail(where, "command " + e.name, tick, r, expected, n == 0 ? "not sent" : n == 1 ? "sent once" : "sent " + std::to_string(n) + " times");
      else
        pass(where, "command " + e.name + " " + expected);
      return;
    }
    case ScenarioExpectation::Kind::sanitizer: {
      const Sanitizer& s = board_.sanitizer();
      Resolved board_wide = r;
      board_wide.label = "the board";
      if (s.broken() == 0)
        pass(where, "sanitizer clean (check=" + std::string(to_string(s.level())) + ")");
      else
        fail(where, "driver sanitizer", tick, board_wide, "no rule broken",
             std::to_string(s.broken()) + " broken, the first " + violation_line(*s.first_broken()));
      return;
    }
    case ScenarioExpectation::Kind::frames: {
      const std::uint64_t n = board_.chain(r.chain).frames();
      auto text = [](std::uint64_t v) { return v == UINT64_MAX ? std::string("any") : std::to_string(v); };
      const std::string expected =
          e.min_count == e.max_count ? text(e.min_count) : text(e.min_count) + " .. " + text(e.max_count);
      Resolved chain_only = r;
      chain_only.label = board_.chain_name(r.chain);
      if (n < e.min_count || n > e.max_count)
        fail(where, "frames", tick, chain_only, expected, std::to_string(n));
      else
        pass(where, "frames = " + std::to_string(n));
      return;
    }
  }
}

void ScenarioRunner::finish() {
  if (finished_) return;
  finished_ = true;
  const Tick now = board_.time().now();
  for (std::size_t c = 0; c < board_.chain_count(); ++c) board_.now(c);
  take_events(now);
  fire_due_times(now);
  fire_positions(now);
  for (std::size_t i = 0; i < state_.size(); ++i) {
    StepState& s = state_[i];
    const ScenarioStep& st = scenario_.steps[i];
    if (s.done) continue;
    if (st.when.kind == ScenarioTrigger::Kind::end) {
      fire(i, now);
      continue;
    }
    s.done = true;
    const std::string trigger = std::string(to_string(st.when.kind));
    if (st.expect) {
      ++judged_;
      fail(st.where, std::string(to_string(st.expect->kind)), now, s.target_chip, "its trigger (" + trigger + ")",
           "the program ended first");
    } else {
      log_.push_back(seconds_text(now) + ": " + st.where + ": " + trigger + " never came: the action was not applied");
    }
  }
}

ScenarioOutcome ScenarioRunner::outcome() const {
  ScenarioOutcome o;
  o.judged = judged_;
  o.failures = failures_;
  o.passed = passed_;
  o.log = log_;
  for (std::size_t c = 0; c < board_.chain_count(); ++c)
    for (std::size_t k = 0; k < board_.chip_count(c); ++k)
      for (const Pin p : {Pin::BUSY, Pin::FLAG})
        if (const Tick t = board_.last_output_read(c, k, p); t != kNever)
          o.pin_reads.push_back({board_.chain_name(c), board_.chip_numbering(c).number_of(k), p == Pin::BUSY ? "BUSY" : "FLAG", t});
  return o;
}

}  // namespace l6470emu
