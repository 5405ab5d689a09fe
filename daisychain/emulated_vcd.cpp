// export_emulated_vcd: walks the trace with a ProtocolTracker (so frames and pins reach the
// chain exactly as in a replay) and samples the chips' outputs and positions in between.
#include "daisychain/emulated_vcd.hpp"

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "daisychain/phase_drive.hpp"
#include "daisychain/protocol_tracker.hpp"
#include "spi/export_vcd.hpp"

namespace l6470emu {
namespace {

struct ChipWires {
  int busy, flag, sw, stck, stby, abs_pos, coil_a, coil_b;
  int dir = -1;  // a chip with a DIR input (the L6474) only
};

}  // namespace

void export_emulated_vcd(const TracePasses& passes, Chain& chain, std::ostream& out, const EmulatedVcdOptions& options) {
  VcdWriter w(out, options.timescale_ns);
  SpiVcdWaveform spi(w);
  const std::size_t n = chain.size();
  std::vector<ChipWires> wires(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::string scope = "chip" + std::to_string(k);
    const Chip& c = chain.chip(k);
    const PhaseDrive d = phase_drive(c);
    wires[k] = {w.wire(scope, "BUSY", c.busy_sync_pin()), w.wire(scope, "FLAG", c.flag_pin()),
                w.wire(scope, "SW", c.sw_pin()),          w.wire(scope, "STCK", false),
                w.wire(scope, "STBY", c.spi_enabled()),   w.number(scope, "ABS_POS", c.position()),
                w.number(scope, "COIL_A", d.coil_a),      w.number(scope, "COIL_B", d.coil_b)};
    if (c.variant().pins.dir) wires[k].dir = w.wire(scope, "DIR", c.dir_pin());
  }
  ProtocolTracker tracker(chain);
  const Tick step = std::max<Tick>(options.sample_ticks, 1);

  auto look = [&](Tick t) {
    const std::uint64_t ns = ns_from_ticks(t);
    for (std::size_t k = 0; k < n; ++k) {
      const Chip& c = chain.chip(k);
      w.change(ns, wires[k].busy, c.busy_sync_pin());
      w.change(ns, wires[k].flag, c.flag_pin());
      w.change(ns, wires[k].abs_pos, c.position());
      const PhaseDrive d = phase_drive(c);
      w.change(ns, wires[k].coil_a, d.coil_a);
      w.change(ns, wires[k].coil_b, d.coil_b);
    }
  };
  // Samples from the chain's time up to (not including) `until` while anything moves.
  auto run_until = [&](Tick until) {
    while (chain.now() < until) {
      if (chain.next_event_tick() == kNever) {
        chain.advance_to(until);
        return;
      }
      const Tick t = std::min(until, chain.now() + step);
      chain.advance_to(t);
      look(t);
    }
  };

  std::vector<std::uint8_t> rx;
  std::uint64_t end_ns = 0;
  std::unique_ptr<TraceReader> events = passes();
  NextFrameTicks next(passes());
  TraceEvent e;
  while (events->next(e)) {
    run_until(e.tick);
    if (e.kind == TraceEventKind::frame) {
      const std::optional<Tick> limit = next.after_frame();
      end_ns = std::max(end_ns, spi.draw(e, limit ? ns_from_ticks(*limit) : 0));
      rx.resize(e.mosi.size());
      tracker.begin_frame(e, rx);
      tracker.end_frame();
      look(e.end());
      continue;
    }
    if (e.chip >= n)
      throw TraceError(events->header().name, e.line, trace_chip_outside_chain(e.chip, n));
    tracker.apply(e);
    const std::uint64_t ns = ns_from_ticks(e.tick);
    if (e.kind == TraceEventKind::pin) {
      if (e.pin == TracePin::SW || e.pin == TracePin::SW_AXIS) w.change(ns, wires[e.chip].sw, e.value);
      if (e.pin == TracePin::STCK) w.change(ns, wires[e.chip].stck, e.value);
      if (e.pin == TracePin::STBY) w.change(ns, wires[e.chip].stby, e.value);
      if (e.pin == TracePin::DIR && wires[e.chip].dir >= 0) w.change(ns, wires[e.chip].dir, e.value);
    }
    look(e.tick);
    end_ns = std::max(end_ns, ns);
  }
  // Let a move that is still going finish (at most one more second), so its end shows.
  const Tick stop = std::max(chain.now(), static_cast<Tick>(end_ns / 250)) + kTicksPerSecond;
  while (chain.next_event_tick() != kNever && chain.now() < stop) run_until(std::min(stop, chain.now() + step * 64));
  w.finish(std::max(end_ns, ns_from_ticks(chain.now())) + 1000);
}

void export_emulated_vcd(const Trace& trace, Chain& chain, std::ostream& out, const EmulatedVcdOptions& options) {
  export_emulated_vcd([&trace] { return trace.reader(); }, chain, out, options);
}

}  // namespace l6470emu
