// CoverageCollector: the points a run hits, kept as one flag per point of each chip's universe.
#include "board/coverage_collector.hpp"

namespace l6470emu {

namespace {

constexpr std::uint32_t kPositionMask = 0x3FFFFF;  // 22-bit ABS_POS / N arguments
constexpr std::uint32_t kSpeedMask = 0xFFFFF;      // Run's 20-bit SPD

}  // namespace

void CoverageCollector::add_chain(const Chain& chain, NumberFrom numbering) {
  const ChipNumbering numbers(numbering, chain.size());
  std::vector<ChipState> chips(chain.size());
  for (std::size_t k = 0; k < chain.size(); ++k) {
    ChipState& s = chips[k];
    const Chip& c = chain.chip(k);
    s.universe = &coverage_universe(c.variant());
    s.variant = s.universe->variant();
    s.position = chain_position_name(numbers.number_of(k), chain.size());
    s.hit.assign(s.universe->points().size(), 0);
    s.flags = status_flag_points(c.status_layout());
    for (const StatusFlagPoint& f : s.flags) {
      s.raised_index.push_back(s.universe->find(CoverageCategory::flags_raised, f.name));
      s.observed_index.push_back(s.universe->find(CoverageCategory::flags_observed, f.name));
    }
    s.get_status_index = s.universe->find(CoverageCategory::commands, "GetStatus");
  }
  chains_.push_back(std::move(chips));
  looks_.push_back(ChainLook{});
}

CoverageCollector::ChipState& CoverageCollector::chip(std::size_t chain, std::size_t chip) {
  return chains_.at(chain).at(chip);
}

void CoverageCollector::mark(ChipState& s, CoverageCategory c, std::string_view name) {
  mark_index(s, s.universe->find(c, name));
}

void CoverageCollector::settle(ChipState& s) {
  if (!s.has_pending) return;
  s.has_pending = false;
  if (s.pending.command == Command::SetParam)
    mark(s, CoverageCategory::registers_written, s.pending_register);
  else
    mark(s, CoverageCategory::step_modes, step_mode_name(s.pending_step_sel));
}

void CoverageCollector::saw_status(ChipState& s, std::uint16_t status, bool observed) {
  if (static_cast<std::int32_t>(status) != s.last_raised_status) {
    s.last_raised_status = status;
    for (std::size_t i = 0; i < s.flags.size(); ++i)
      if (s.flags[i].set_in(status)) mark_index(s, s.raised_index[i]);
  }
  if (observed && static_cast<std::int32_t>(status) != s.last_observed_status) {
    s.last_observed_status = status;
    for (std::size_t i = 0; i < s.flags.size(); ++i)
      if (s.flags[i].set_in(status)) mark_index(s, s.observed_index[i]);
  }
}

void CoverageCollector::command(std::size_t chain, std::size_t k, const Chip& c, const Opcode& op, std::uint32_t arg) {
  ChipState& s = chip(chain, k);
  settle(s);
  s.addressed = true;
  if (op.command == Command::GetStatus) {
    mark_index(s, s.get_status_index);
    saw_status(s, c.status(), true);
    return;
  }
  if (op.command != Command::GetParam) looks_[chain].dirty = true;  // reads raise no flag
  const std::string name(to_string(op.command));
  switch (op.command) {
    case Command::NOP: case Command::Reserved: case Command::Unknown:
      return;
    case Command::GetParam: {
      const RegisterInfo* r = c.registers().at_address(op.param);
      if (!r) return;
      mark(s, CoverageCategory::registers_read, r->name);
      if (r->id == Reg::STATUS) saw_status(s, c.status(), true);
      return;
    }
    case Command::SetParam: {
      const RegisterInfo* r = c.registers().at_address(op.param);
      if (!r) return;
      s.pending = op;
      s.pending_register = r->name;
      s.has_pending = true;
      return;
    }
    case Command::Run:
      mark(s, CoverageCategory::commands, name + (op.dir ? " FWD" : " REV"));
      if ((std::uint64_t{arg & kSpeedMask} << 12) > c.profile().max_speed) mark(s, CoverageCategory::commands, "Run above MAX_SPEED");
      break;
    case Command::StepClock:
    case Command::GoTo_DIR:
      mark(s, CoverageCategory::commands, name + (op.dir ? " FWD" : " REV"));
      if (op.command == Command::GoTo_DIR && sign_extend(arg & kPositionMask, 22) == c.position())
        mark(s, CoverageCategory::commands, "GoTo_DIR to the current position");
      break;
    case Command::Move:
      mark(s, CoverageCategory::commands, name + (op.dir ? " FWD" : " REV"));
      if ((arg & kPositionMask) == 0) mark(s, CoverageCategory::commands, "Move of 0 steps");
      break;
    case Command::GoTo:
      mark(s, CoverageCategory::commands, name);
      if (sign_extend(arg & kPositionMask, 22) == c.position()) mark(s, CoverageCategory::commands, "GoTo to the current position");
      break;
    case Command::GoUntil:
    case Command::ReleaseSW:
      mark(s, CoverageCategory::commands, name + (op.dir ? " FWD" : " REV"));
      mark(s, CoverageCategory::commands, name + (op.act ? " ACT=1" : " ACT=0"));
      break;
    default:
      mark(s, CoverageCategory::commands, name);
      break;
  }
  if (is_motion_command(op.command) || op.command == Command::Enable) {  // the L6474's step mode: Enable's
    s.pending = op;
    s.pending_step_sel = c.profile().step_sel;
    s.has_pending = true;
  }
}

void CoverageCollector::diagnostic(std::size_t chain, std::size_t k, const Diagnostic& d) {
  ChipState& s = chip(chain, k);
  looks_[chain].dirty = true;  // WRONG_CMD / NOTPERF_CMD latched
  const bool pending = s.has_pending;
  s.has_pending = false;  // refused: neither written nor run
  if (d.detail == DiagnosticDetail::read_only_write) return mark(s, CoverageCategory::refusals, "SetParam of a read-only register");
  if (d.kind == DiagnosticKind::wrong_cmd) return mark(s, CoverageCategory::refusals, "an opcode that is no command");
  if (d.kind != DiagnosticKind::notperf_cmd) return;
  switch (d.detail) {
    case DiagnosticDetail::refused_fault_hiz:
      return mark(s, CoverageCategory::refusals, "motion command while a fault holds HiZ");
    case DiagnosticDetail::refused_busy:
      if (pending) mark(s, CoverageCategory::refusals, std::string(to_string(s.pending.command)) + " while BUSY");
      return;
    case DiagnosticDetail::refused_running:
    case DiagnosticDetail::refused_bridges_on:
      if (pending && s.pending.command == Command::SetParam)
        mark(s, CoverageCategory::refusals, "SetParam(" + std::string(s.pending_register) + ")");
      else if (pending)
        mark(s, CoverageCategory::refusals, std::string(to_string(s.pending.command)) + " while the motor runs");
      else if (d.detail == DiagnosticDetail::refused_bridges_on)
        mark(s, CoverageCategory::refusals, "ResetDevice while the bridges are enabled");
      return;
    default:
      return;
  }
}

void CoverageCollector::look(std::size_t chain, const Chain& ch, bool force) {
  auto& chips = chains_.at(chain);
  ChainLook& last = looks_[chain];
  if (!force && last.looked && !last.dirty && ch.now() - last.at < kLookInterval) return;
  last.looked = true;
  last.dirty = false;
  last.at = ch.now();
  for (std::size_t k = 0; k < chips.size() && k < ch.size(); ++k) {
    ChipState& s = chips[k];
    settle(s);
    const Chip& c = ch.chip(k);
    if (!c.spi_enabled()) continue;  // in standby STATUS reads as nothing
    saw_status(s, c.status(), false);
    if (c.has_axis()) {  // the axis's switches drive SW
      const bool low = !c.sw_pin();
      if (low && !s.sw_low) mark(s, CoverageCategory::events, "SW closed");
      if (!low && s.sw_low) mark(s, CoverageCategory::events, "SW opened");
      s.sw_low = low;
    }
  }
}

void CoverageCollector::event(std::size_t chain, std::size_t k, TraceFault fault, std::uint8_t value) {
  ChipState& s = chip(chain, k);
  looks_[chain].dirty = true;  // the next look looks
  switch (fault) {
    case TraceFault::THERMAL:
      if (value >= 1 && value <= 3) mark(s, CoverageCategory::events, "THERMAL " + std::string(thermal_name(value)));
      return;
    case TraceFault::UVLO: case TraceFault::UVLO_ADC: case TraceFault::OCD: case TraceFault::STALL_A: case TraceFault::STALL_B:
      if (value == 0) return;  // the condition ends
      [[fallthrough]];
    default:
      mark(s, CoverageCategory::events, to_string(fault));
  }
}

void CoverageCollector::input(std::size_t chain, std::size_t k, Pin pin, bool level) {
  ChipState& s = chip(chain, k);
  looks_[chain].dirty = true;  // the next look looks
  if (pin == Pin::SW) {
    if (!level && !s.sw_low) mark(s, CoverageCategory::events, "SW closed");
    if (level && s.sw_low) mark(s, CoverageCategory::events, "SW opened");
    s.sw_low = !level;
  } else if (pin == Pin::STBY_RST) {
    if (level && s.stby_low) mark(s, CoverageCategory::events, "STBY_RST reset");
    s.stby_low = !level;
  }
}

void CoverageCollector::output_read(std::size_t chain, std::size_t k, const Chip& c, Pin pin, bool level) {
  if (!pin_is_chip_output(pin)) return;
  ChipState& s = chip(chain, k);
  std::int8_t& last = s.last_read[pin == Pin::FLAG ? 1 : 0];
  if (last >= 0 && (last != 0) != level) mark(s, CoverageCategory::pin_edges, std::string(pin_name(pin)) + (level ? " rising" : " falling"));
  last = level ? 1 : 0;
  if (level || !c.spi_enabled()) return;  // an output pulled low is the one that says something
  // BUSY low observes BUSY when it is BUSY (with STEP_MODE.SYNC_EN the pin is SYNC); FLAG low,
  // every alarm flag set.
  const std::uint16_t status = c.status();
  for (std::size_t i = 0; i < s.flags.size(); ++i)
    if (s.flags[i].set_in(status) && (pin == Pin::BUSY ? s.flags[i].name == "BUSY" : s.flags[i].alarm))
      mark_index(s, s.observed_index[i]);
}

void CoverageCollector::output_edge(std::size_t chain, std::size_t k, Pin pin, bool rising) {
  if (!pin_is_chip_output(pin)) return;
  ChipState& s = chip(chain, k);
  mark(s, CoverageCategory::pin_edges, std::string(pin_name(pin)) + (rising ? " rising" : " falling"));
  s.last_read[pin == Pin::FLAG ? 1 : 0] = rising ? 1 : 0;
}

void CoverageCollector::rule_broken(std::size_t chain, std::optional<std::size_t> k, Rule rule) {
  if (chain >= chains_.size()) return;
  auto& chips = chains_[chain];
  for (std::size_t i = 0; i < chips.size(); ++i)
    if (!k || *k == i) mark(chips[i], CoverageCategory::rules_broken, rule_info(rule).name);
}

CoverageData CoverageCollector::data() const {
  CoverageData d;
  for (const auto& chips : chains_)
    for (const ChipState& s0 : chips) {
      ChipState s = s0;  // a write still pending counts as done
      settle(s);
      CoverageData::PerVariant& v = d.use(s.variant);
      v.positions.insert(s.position);
      if (s.addressed) v.hit[static_cast<std::size_t>(CoverageCategory::chain_positions)].insert(s.position);
      const auto& points = s.universe->points();
      for (std::size_t i = 0; i < points.size(); ++i)
        if (s.hit[i]) v.hit[static_cast<std::size_t>(points[i].category)].insert(points[i].name);
    }
  return d;
}

}  // namespace l6470emu
