// The campaign's plan: the fault catalogue, the clean run read back from its recording through
// the protocol tracker (the same shadow chain decode uses), injection points and rerun steps.
#include "tools/campaign_plan.hpp"

#include <algorithm>
#include <map>

#include "core/registers.hpp"
#include "daisychain/protocol_tracker.hpp"
#include "spi/trace.hpp"
#include "tools/trace_input.hpp"
#include "tools/trace_world.hpp"

namespace l6470emu {
namespace {

constexpr FaultSpec kFaults[] = {
    {CampaignFault::ocd, "ocd", "OCD", "an overcurrent in a bridge for 10 ms: OCD latched, and with CONFIG.OC_SD the bridges shut down (HiZ)"},
    {CampaignFault::thermal_warning, "thermal_warning", "TH_WRN", "the die reaches its warning temperature for 10 ms: TH_WRN latched"},
    {CampaignFault::thermal_bridge_shutdown, "thermal_bridge_shutdown", "TH_SD",
     "the die reaches its bridge shutdown temperature for 10 ms: TH_SD latched, the bridges go HiZ"},
    {CampaignFault::thermal_device_shutdown, "thermal_device_shutdown", "TH_SD",
     "the die reaches its device shutdown temperature for 10 ms: TH_SD latched, the bridges go HiZ"},
    {CampaignFault::uvlo, "uvlo", "UVLO", "the motor supply dips below the UVLO threshold for 10 ms: UVLO latched, the bridges go HiZ"},
    {CampaignFault::uvlo_adc, "uvlo_adc", "UVLO_ADC", "the ADC input dips below its UVLO threshold for 10 ms (gate-driver parts): UVLO_ADC latched"},
    {CampaignFault::stall_a, "stall_a", "STEP_LOSS_A", "a stall (step loss) on bridge A: STEP_LOSS_A / STALL_A latched"},
    {CampaignFault::stall_b, "stall_b", "STEP_LOSS_B", "a stall (step loss) on bridge B: STEP_LOSS_B / STALL_B latched"},
    {CampaignFault::sw_close, "sw_close", "SW_EVN", "the switch on SW closes for 10 ms when nothing expects it: SW_EVN latched (SW_F while closed); with CONFIG.SW_MODE = 0 a HardStop"},
    {CampaignFault::reset, "reset", "UVLO", "a brown-out: the chip loses power and comes back, registers at reset values, bridges HiZ, UVLO latched"},
    {CampaignFault::stby_pulse, "stby_pulse", "UVLO", "STBY\\RST pulled low for 10 ms: the logic is held in reset and comes back at power-up state"},
    {CampaignFault::miso_flip, "miso_flip", "", "one bit (the MSB) of the chip's answer byte in the next CS frame is inverted on the wire"},
    {CampaignFault::lost_frame, "lost_frame", "", "the next CS frame never reaches the chip: it neither shifts nor decodes its bytes"},
    {CampaignFault::block, "block", "STEP_LOSS_A", "a hard stop in the way of the rotor where it is: the motor stalls against it (boards with an axis)"},
};

// Enable is where an L6474 (no motion command) starts to be driven: its phase like a motion's.
bool is_motion(Command c) { return is_motion_command(c) || c == Command::Enable; }
bool is_config(Command c) { return c == Command::SetParam || c == Command::ResetDevice || c == Command::ResetPos; }
bool is_poll(Command c) { return c == Command::GetStatus || c == Command::GetParam; }

// Calls `on_event` for each event of the trace after running it through a tracker on `chain`;
// `before` is called with each event's tick before the event is applied.
template <class Before>
void walk(const std::string& path, Chain& chain, const ProtocolTracker::Observer& observer, Before&& before,
          const std::function<void(const TraceEvent&)>& on_event) {
  TraceFile file(path, TraceInputOptions{});
  auto reader = file.read();
  ProtocolTracker tracker(chain, observer);
  TraceEvent e;
  std::vector<std::uint8_t> rx;
  while (reader->next(e)) {
    before(e.tick);
    on_event(e);
    if (e.kind == TraceEventKind::frame) {
      rx.resize(e.mosi.size());
      tracker.begin_frame(e, rx);
      tracker.end_frame();
      continue;
    }
    tracker.apply(e);
  }
  tracker.finish();
}

Chain chain_of_trace(const std::string& path) {
  TraceFile file(path, TraceInputOptions{});
  return world_for_trace(WorldOptions{}, file).make_chain();
}

ScenarioStep at_step(Tick tick, const ChipRun& chip, ScenarioAction a) {
  ScenarioStep s;
  s.when.kind = ScenarioTrigger::Kind::time;
  s.when.tick = tick;
  a.chip = ScenarioChip{chip.chain_name, chip.number};
  s.action = a;
  return s;
}

}  // namespace

std::span<const FaultSpec> campaign_faults() { return kFaults; }

const FaultSpec* find_campaign_fault(std::string_view name) {
  for (const FaultSpec& f : kFaults)
    if (f.name == name) return &f;
  return nullptr;
}

std::string fault_unavailable(CampaignFault fault, const Variant& variant, bool has_axis) {
  switch (fault) {
    case CampaignFault::uvlo_adc:
      if (variant.status.uvlo_adc < 0) return std::string(variant.name) + " has no ADC undervoltage detection (UVLO_ADC)";
      break;
    case CampaignFault::stall_a:
    case CampaignFault::stall_b:
      if ((fault == CampaignFault::stall_a ? variant.status.step_loss_a : variant.status.step_loss_b) < 0)
        return std::string(variant.name) + " has no stall detection";
      break;
    case CampaignFault::sw_close:
      if (!variant.pins.sw) return std::string(variant.name) + " has no SW input";
      break;
    case CampaignFault::block:
      if (!has_axis) return "the chip has no axis (axis.K= in the board description)";
      break;
    default:
      break;
  }
  return "";
}

std::string fault_flag(CampaignFault fault, const Variant& variant) {
  const FaultSpec* spec = nullptr;
  for (const FaultSpec& f : kFaults)
    if (f.fault == fault) spec = &f;
  if (!spec || spec->flag.empty()) return "";
  if (spec->flag == "STEP_LOSS_A") return std::string(variant.status.step_loss_a_name);
  if (spec->flag == "STEP_LOSS_B") return std::string(variant.status.step_loss_b_name);
  return std::string(spec->flag);
}

std::vector<ChipRun> read_clean_run(const std::string& trace_path, std::size_t chain_index, const BoardConfig& board,
                                    Tick end_tick) {
  const ChainConfig& cc = board.chains.at(chain_index);
  Chain chain = chain_of_trace(trace_path);
  const ChipNumbering numbering(board.numbering, chain.size());
  std::string name = cc.path.empty() ? "spidev" + std::to_string(cc.bus) + "." + std::to_string(cc.cs) : cc.path;
  if (const auto slash = name.rfind('/'); slash != std::string::npos) name = name.substr(slash + 1);
  std::vector<ChipRun> chips(chain.size());
  for (std::size_t k = 0; k < chips.size(); ++k) {
    chips[k].chain = chain_index;
    chips[k].index = k;
    chips[k].number = numbering.number_of(k);
    chips[k].chain_name = name;
    chips[k].variant = &chain.chip(k).variant();
    chips[k].has_axis = chain.chip(k).has_axis();
  }
  Tick frame_end = 0;
  walk(
      trace_path, chain,
      [&](const ProtocolEvent& e) {
        if (e.kind != ProtocolEvent::Kind::command || e.chip >= chips.size() || e.op.command == Command::NOP) return;
        chips[e.chip].commands.push_back(DecodedCommand{e.op.command, e.op.param, e.tick, frame_end});
      },
      [](Tick) {},
      [&](const TraceEvent& e) {
        if (e.kind == TraceEventKind::frame) frame_end = e.end();
        if (!e.is_observation() || e.pin != TracePin::BUSY || e.chip >= chips.size()) return;
        auto& low = chips[e.chip].busy_low;
        const bool open = !low.empty() && low.back().second == kNever;
        if (e.value == 0 && !open) low.emplace_back(e.tick, kNever);
        if (e.value != 0 && open) low.back().second = e.tick;
      });
  if (chain.now() < end_tick) chain.advance_to(end_tick);
  for (ChipRun& c : chips) {
    const Chip& chip = chain.chip(c.index);
    std::vector<std::uint8_t> written;
    for (const DecodedCommand& d : c.commands)
      if (d.command == Command::SetParam && std::find(written.begin(), written.end(), d.param) == written.end())
        written.push_back(d.param);
    std::vector<const RegisterInfo*> regs{chip.registers().find(Reg::ABS_POS), chip.registers().find(Reg::MARK)};
    std::sort(written.begin(), written.end());
    for (const std::uint8_t a : written)
      if (const RegisterInfo* r = chip.registers().at_address(a); r && std::find(regs.begin(), regs.end(), r) == regs.end())
        regs.push_back(r);
    for (const RegisterInfo* r : regs) {
      if (!r) continue;
      const std::uint32_t raw = chip.peek(r->id) & r->mask();
      c.final_registers.emplace_back(std::string(r->name), r->is_signed() ? sign_extend(raw, r->bits) : std::int64_t{raw});
    }
    const std::uint16_t status = chip.status();
    const StatusLayout& l = chip.status_layout();
    c.final_status = {{"HiZ", (status >> l.hiz) & 1u}};
    if (l.busy >= 0) c.final_status.emplace_back("BUSY", (status >> l.busy) & 1u);  // not on an L6474
    c.final_status.emplace_back("DIR", (status >> l.dir) & 1u);
  }
  return chips;
}

void sample_rotor_positions(const std::string& trace_path, std::size_t, const BoardConfig&, std::vector<ChipRun>& chips,
                            const std::vector<std::vector<Tick>>& ticks_per_chip) {
  std::vector<std::pair<Tick, std::size_t>> samples;  // (tick, chip index)
  for (std::size_t k = 0; k < chips.size() && k < ticks_per_chip.size(); ++k)
    if (chips[k].has_axis)
      for (const Tick t : ticks_per_chip[k]) samples.emplace_back(t, k);
  if (samples.empty()) return;
  std::sort(samples.begin(), samples.end());
  Chain chain = chain_of_trace(trace_path);
  std::size_t next = 0;
  auto take_until = [&](Tick tick) {
    for (; next < samples.size() && samples[next].first <= tick; ++next) {
      if (chain.now() < samples[next].first) chain.advance_to(samples[next].first);
      const Chip& chip = chain.chip(samples[next].second);
      chips[samples[next].second].rotor_at.emplace_back(samples[next].first, chip.axis() ? chip.axis()->true_position() : 0);
    }
  };
  walk(trace_path, chain, {}, [&](Tick t) { take_until(t > 0 ? t - 1 : 0); }, [](const TraceEvent&) {});
  take_until(kNever - 1);
}

std::vector<InjectionPoint> injection_points(const ChipRun& chip, PointSelection selection) {
  std::vector<InjectionPoint> points;
  const auto& cmds = chip.commands;
  if (cmds.empty()) return points;
  const Tick last = cmds.back().start;
  // The command decoded last before `tick` ("" none).
  auto before = [&](Tick tick) {
    std::string name;
    for (const DecodedCommand& d : cmds)
      if (d.end < tick) name = std::string(to_string(d.command));
    return name;
  };
  std::map<std::string, int> used;
  auto add = [&](std::string name, Tick tick) {
    if (tick >= last) return;
    for (const InjectionPoint& p : points)
      if (p.tick == tick) return;
    const int n = ++used[name];
    if (n > 1) name += "_" + std::to_string(n);
    points.push_back(InjectionPoint{name, tick, before(tick)});
  };
  if (selection == PointSelection::every_command) {
    for (std::size_t i = 0; i + 1 < cmds.size(); ++i) add("after_" + std::string(to_string(cmds[i].command)), cmds[i].end + 1);
  } else {
    const auto first_motion = std::find_if(cmds.begin(), cmds.end(), [](const DecodedCommand& d) { return is_motion(d.command); });
    for (auto it = first_motion; it != cmds.begin();) {
      --it;
      if (is_config(it->command)) {
        add("after_config", it->end + 1);
        break;
      }
    }
    for (const DecodedCommand& d : cmds)
      if (is_motion(d.command)) add("at_" + std::string(to_string(d.command)), d.end + 1);
    for (const auto& [from, to] : chip.busy_low) {
      const Tick end = std::min(to, last);
      if (end > from + 1) add("during_motion", from + (end - from) / 2);
    }
    const auto busy_at = [&](Tick t) {
      for (const auto& [from, to] : chip.busy_low)
        if (t >= from && t < to) return true;
      return false;
    };
    const Tick idle_from = first_motion == cmds.end() ? 0 : first_motion->end;
    for (std::size_t i = 0; i + 1 < cmds.size(); ++i) {
      const DecodedCommand &a = cmds[i], &b = cmds[i + 1];
      if (a.start >= idle_from && is_poll(a.command) && is_poll(b.command) && !busy_at(a.end) && !busy_at(b.start) &&
          b.start > a.end + 1) {
        add("idle_polling", a.end + (b.start - a.end) / 2);
        break;
      }
    }
    if (last > 0) add("before_last_command", last - 1);
  }
  std::stable_sort(points.begin(), points.end(), [](const InjectionPoint& a, const InjectionPoint& b) { return a.tick < b.tick; });
  return points;
}

std::vector<ScenarioStep> fault_steps(CampaignFault fault, const ChipRun& chip, Tick tick, std::int64_t rotor) {
  std::vector<ScenarioStep> steps;
  const Tick clear = tick + kFaultHoldTicks;
  // A backdoor condition raised (value `on`) and, kFaultHoldTicks later, ended (value `off`).
  auto condition = [&](TraceFault f, std::uint8_t on = 1, std::uint8_t off = 0) {
    ScenarioAction a;
    a.kind = ScenarioAction::Kind::fault;
    a.fault = f;
    a.value = on;
    steps.push_back(at_step(tick, chip, a));
    a.value = off;
    steps.push_back(at_step(clear, chip, a));
  };
  auto pin = [&](ScenarioAction::Kind kind) {
    ScenarioAction a;
    a.kind = kind;
    a.level = false;
    steps.push_back(at_step(tick, chip, a));
    a.level = true;
    steps.push_back(at_step(clear, chip, a));
  };
  switch (fault) {
    case CampaignFault::ocd: condition(TraceFault::OCD); break;
    case CampaignFault::thermal_warning: condition(TraceFault::THERMAL, 1); break;
    case CampaignFault::thermal_bridge_shutdown: condition(TraceFault::THERMAL, 2); break;
    case CampaignFault::thermal_device_shutdown: condition(TraceFault::THERMAL, 3); break;
    case CampaignFault::uvlo: condition(TraceFault::UVLO); break;
    case CampaignFault::uvlo_adc: condition(TraceFault::UVLO_ADC); break;
    case CampaignFault::stall_a: condition(TraceFault::STALL_A); break;
    case CampaignFault::stall_b: condition(TraceFault::STALL_B); break;
    case CampaignFault::sw_close: pin(ScenarioAction::Kind::sw); break;
    case CampaignFault::stby_pulse: pin(ScenarioAction::Kind::stby_rst); break;
    case CampaignFault::block: {
      ScenarioAction a;
      a.kind = ScenarioAction::Kind::block;
      a.position = rotor;
      steps.push_back(at_step(tick, chip, a));
      break;
    }
    case CampaignFault::reset:
    case CampaignFault::miso_flip:
    case CampaignFault::lost_frame: {  // events of a moment: nothing to clear
      ScenarioAction a;
      a.kind = ScenarioAction::Kind::fault;
      a.fault = fault == CampaignFault::reset ? TraceFault::POWER_CYCLE
                : fault == CampaignFault::miso_flip ? TraceFault::MISO_FLIP : TraceFault::LOST_FRAME;
      a.value = fault == CampaignFault::miso_flip ? 7 : 0;
      steps.push_back(at_step(tick, chip, a));
      break;
    }
  }
  return steps;
}

std::vector<ScenarioStep> clean_run_oracle(const std::vector<ChipRun>& chips) {
  std::vector<ScenarioStep> steps;
  auto at_end = [&](ScenarioExpectation e) {
    ScenarioStep s;
    s.where = "the clean run's end";
    s.when.kind = ScenarioTrigger::Kind::end;
    s.expect = std::move(e);
    steps.push_back(std::move(s));
  };
  for (const ChipRun& c : chips) {
    if (c.commands.empty()) continue;  // a chip the driver never spoke to is left out
    ScenarioExpectation e;
    e.chip = ScenarioChip{c.chain_name, c.number};
    e.kind = ScenarioExpectation::Kind::reg;
    for (const auto& [name, value] : c.final_registers) {
      e.name = name;
      e.value = value;
      at_end(e);
    }
    e.kind = ScenarioExpectation::Kind::status;
    e.name.clear();
    e.value = 0;
    e.flags = c.final_status;
    at_end(e);
  }
  return steps;
}

std::vector<std::string> comma_list(std::string_view list) {
  std::vector<std::string> out;
  for (std::size_t at = 0; at <= list.size();) {
    const std::size_t comma = std::min(list.find(',', at), list.size());
    out.emplace_back(list.substr(at, comma - at));
    at = comma + 1;
  }
  return out;
}

bool has_expectations(const Scenario& scenario) {
  return std::any_of(scenario.steps.begin(), scenario.steps.end(), [](const ScenarioStep& s) { return s.expect.has_value(); });
}

}  // namespace l6470emu
