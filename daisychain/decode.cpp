// decode_trace: formats ProtocolTracker events, one line each, and rate-limits repeated
// diagnostics so a host that always sends the wrong frame length does not drown the log.
#include "daisychain/decode.hpp"
#include "core/counted.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "daisychain/divergence.hpp"
#include "daisychain/explain.hpp"
#include "daisychain/protocol_tracker.hpp"

namespace l6470emu {
namespace {

std::string stamp(double seconds) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "t=%.6f s  ", seconds);
  return buf;
}


const char* issue_name(ProtocolEvent::Issue i) {
  switch (i) {
    case ProtocolEvent::Issue::wrong_cmd: return "WRONG_CMD";
    case ProtocolEvent::Issue::notperf_cmd: return "NOTPERF_CMD";
    case ProtocolEvent::Issue::chain_length: return "frame length";
    case ProtocolEvent::Issue::standby: return "standby";
    case ProtocolEvent::Issue::answer_lost: return "answer lost";
    case ProtocolEvent::Issue::none: break;
  }
  return "diagnostic";
}

class Decoder {
 public:
  Decoder(std::ostream& out, const DecodeOptions& options, const std::string& name, ChipNumbering numbering)
      : out_(out), options_(options), name_(name), numbering_(numbering) {}

  void on_event(const ProtocolEvent& e) {
    if (!shown(e.chip)) return;
    const double t = display_seconds(e.tick, e.source_time);
    switch (e.kind) {
      case ProtocolEvent::Kind::command: {
        const Command c = e.op.command;
        if (c == Command::GetParam || c == Command::GetStatus) return;  // shown with the answer
        if (c == Command::NOP && !options_.show_nops) return;
        if (c != Command::NOP) ++summary.commands;
        line_ = stamp(t) + chip_column(e.chip) + describe_command(e.opcode, e.arg, *e.table, *e.layout);
        break;
      }
      case ProtocolEvent::Kind::answer: {
        ++summary.answers;
        if (!e.complete) {
          diagnostic(e, t, opcode_name(e.opcode, *e.table) + " answer lost: " + e.text);
          return;
        }
        line_ = stamp(t) + chip_column(e.chip) + describe_answer(e.opcode, e.value, *e.table, *e.layout);
        if (!e.captured) {
          line_ += "  (MISO not captured: the emulator's answer)";
        } else if (e.value != e.emulated) {
          ++summary.answer_mismatches;
          line_ += "  (the emulator answers " + hex_value(e.emulated, 8u * e.answer_bytes) + ")";
        }
        break;
      }
      case ProtocolEvent::Kind::diagnostic:
        // WRONG_CMD and NOTPERF_CMD texts start with the flag's name already.
        diagnostic(e, t,
                   e.issue == ProtocolEvent::Issue::wrong_cmd || e.issue == ProtocolEvent::Issue::notperf_cmd
                       ? e.text
                       : std::string(issue_name(e.issue)) + ": " + e.text);
        return;
    }
    put(t, std::move(line_), e.chip);
  }

  /// The host's wire settings from this frame on (a `wire` line of the trace), on a line of their own.
  void host_wire(double t, const TraceWire& wire) {
    put(t, stamp(t) + "host wire: " + (wire.known ? describe_trace_wire(wire) : "not known (SPI mode 3 assumed)"));
  }

  /// The banner at the first divergence: the log goes on with the emulator's model.
  void divergence(const FirstDivergence& d) {
    put(d.seconds, stamp(d.seconds) + "!!!!!!!! DIVERGED: " + d.summary + "\n" +
                       std::string(stamp(d.seconds).size(), ' ') +
                       "!!!!!!!! from here on this log is the emulator's model of the run, not what the trace holds");
  }

  bool shown(std::size_t chip) const {
    return options_.only_chip < 0 || chip == ProtocolEvent::kNoChip ||
           numbering_.number_of(chip) == static_cast<std::size_t>(options_.only_chip);
  }

  /// A pin or fault line at `t`; `previous_seconds` is when the event before it ended. For a
  /// BUSY/FLAG observation, `edge_seconds` is when the emulated chip's output took the observed
  /// level (NaN when it did not by then), `at_edge` whether that was the observation's own tick.
  void pin(const TraceEvent& e, double t, double previous_seconds, double edge_seconds = NAN, bool at_edge = false) {
    if (!shown(e.chip)) return;
    std::string what;
    const bool level = e.value != 0;
    if (e.kind == TraceEventKind::pin) {
      switch (e.pin) {
        case TracePin::SW: what = level ? "SW pin high (switch open)" : "SW pin low (switch closed)"; break;
        case TracePin::STCK: what = level ? "STCK pin high" : "STCK pin low"; break;
        case TracePin::STBY: what = level ? "STBY\\RST high (out of standby: power-up state)" : "STBY\\RST low (standby)"; break;
        case TracePin::BUSY: what = level ? "BUSY output high (released)" : "BUSY output low (busy)"; break;
        case TracePin::FLAG: what = level ? "FLAG output high (no alarm)" : "FLAG output low (alarm)"; break;
        case TracePin::SW_AXIS: what = level ? "SW high: the axis's switch opened" : "SW low: the axis's switch closed"; break;
        case TracePin::DIR: what = level ? "DIR pin high (forward)" : "DIR pin low (reverse)"; break;
      }
      // STCK edges are as frequent as the steps: show them only with --nops.
      if (e.pin == TracePin::STCK && !options_.show_nops) return;
      // An output level in a trace is an observation: when it was looked at, not when it changed.
      if (is_observed_pin(e.pin)) {
        const bool first = seen_outputs_.insert({e.chip, static_cast<int>(e.pin)}).second;
        if (first) {
          what += ", seen at (its level when watching began)";
        } else if (at_edge) {
          // Recorded at the edge's own tick (a program waiting on the line makes the board step
          // to each edge): the line is the edge, nothing to add.
        } else {
          char buf[64];
          if (edge_seconds == edge_seconds) {
            std::snprintf(buf, sizeof buf, "%.6f", edge_seconds);
            what += std::string(", seen at (the edge was not watched: the emulator's came at t=") + buf + " s)";
          } else {
            std::snprintf(buf, sizeof buf, "%.6f", previous_seconds);
            what += std::string(", seen at (the edge was not watched: it came after t=") + buf + " s)";
          }
        }
      }
    } else if (e.kind == TraceEventKind::axis) {
      what = e.text == "none" ? std::string("axis removed") : "axis attached: " + std::string(e.text);
    } else if (e.kind == TraceEventKind::stops) {
      what = "axis hard stops: " + (e.has_lower_stop ? std::to_string(e.lower_stop) : std::string()) + ".." +
             (e.has_upper_stop ? std::to_string(e.upper_stop) : std::string()) + " (1/128 step)";
    } else if (e.kind == TraceEventKind::supply) {
      what = "axis motor supply: " + std::to_string(e.supply_mV) + " mV";
    } else if (e.kind == TraceEventKind::load) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "axis load: %.2f g·cm² load inertia, %.6f N·m friction, %.6f N·m force",
                    e.load.inertia_g_mm2 / 100.0, e.load.friction_uNm / 1e6, e.load.force_uNm / 1e6);
      what = buf;
    } else {
      what = "fault " + std::string(to_string(e.fault)) + " ";
      if (e.fault == TraceFault::THERMAL) what += thermal_name(e.value);
      else if (e.fault == TraceFault::ADCIN) what = "ADCIN level: ADC_OUT code " + std::to_string(e.value);
      else if (e.fault == TraceFault::POWER_CYCLE) what = "power cycle (brown-out): the chip is back as at power-up";
      else if (e.fault == TraceFault::MISO_FLIP)
        what = "MISO flip: bit " + std::to_string(e.value & 7u) + " of this chip's MISO byte in the next frame inverted";
      else if (e.fault == TraceFault::LOST_FRAME) what = "lost frame: the chip misses the next frame";
      else what += level ? "on" : "off";
    }
    put(t, stamp(t) + chip_column(e.chip) + what, e.chip);
  }

  /// Writes the lines earlier than `watermark` (the start of the oldest answer still being
  /// shifted out, whose line comes later), so the log stays in time order.
  void flush(double watermark) {
    while (!pending_.empty() && pending_.front().t < watermark) {
      out_ << pending_.front().text << '\n';
      pending_.pop_front();
    }
  }

  DecodeSummary summary;

 private:
  /// "chip 2   ": the chip's number as the user counts, in a column.
  std::string chip_column(std::size_t chip) const {
    char buf[24];
    std::snprintf(buf, sizeof buf, "chip %-3zu ", numbering_.number_of(chip));
    return buf;
  }

  void diagnostic(const ProtocolEvent& e, double t, const std::string& text) {
    ++summary.diagnostics;
    const auto key = std::make_pair(e.chip, static_cast<int>(e.issue));
    std::size_t& count = seen_[key];
    ++count;
    if (options_.max_repeats != 0 && count > options_.max_repeats) {
      ++summary.suppressed;
      return;
    }
    std::string where = e.chip == ProtocolEvent::kNoChip ? "frame " + std::to_string(e.frame + 1) + " " : chip_column(e.chip);
    std::string l = stamp(t) + where + "! " + text + "  [" + name_;
    if (e.line) l += ":" + std::to_string(e.line);
    if (e.repetition) l += " repetition " + std::to_string(e.repetition);
    l += ']';
    if (options_.max_repeats != 0 && count == options_.max_repeats) l += "  (further ones of this kind not shown)";
    put(t, std::move(l), e.chip);
  }

  /// Queues a line at time `t`, after the queued lines of earlier times. Among lines of the
  /// same time, a chip's line goes after those of chips the user numbers lower or the same
  /// (the tracker reports chips in chain order, which is the reverse under mosi numbering);
  /// a line of no chip (kNoChip) stays where it came, and chip lines do not move before it.
  void put(double t, std::string line, std::size_t chip = ProtocolEvent::kNoChip) {
    const std::size_t key = chip == ProtocolEvent::kNoChip ? chip : numbering_.number_of(chip);
    auto at = pending_.end();
    while (at != pending_.begin()) {
      const Pending& before = *std::prev(at);
      const bool later = before.t > t || (before.t == t && key != ProtocolEvent::kNoChip &&
                                          before.key != ProtocolEvent::kNoChip && before.key > key);
      if (!later) break;
      --at;
    }
    pending_.insert(at, Pending{t, key, std::move(line)});
  }

  std::ostream& out_;
  const DecodeOptions& options_;
  const std::string& name_;
  ChipNumbering numbering_;
  std::string line_;
  struct Pending {
    double t;         // display time
    std::size_t key;  // the chip's number as shown, or kNoChip
    std::string text;
  };
  std::deque<Pending> pending_;
  std::map<std::pair<std::size_t, int>, std::size_t> seen_;
  std::set<std::pair<std::size_t, int>> seen_outputs_;  // (chip, BUSY/FLAG) looked at before
};

}  // namespace

DecodeSummary decode_trace(TraceReader& in, Chain& chain, std::ostream& out, const DecodeOptions& options) {
  const std::string name = in.header().name;
  if (options.only_chip >= 0 && static_cast<std::size_t>(options.only_chip) >= chain.size())
    throw std::invalid_argument("chip " + std::to_string(options.only_chip) + ": the chain has " +
                                counted(chain.size(), "chip") + " (0.." + std::to_string(chain.size() - 1) + ")");
  Decoder decoder(out, options, name, ChipNumbering(options.number_from, chain.size()));
  ProtocolTracker tracker(chain, [&decoder](const ProtocolEvent& e) { decoder.on_event(e); }, options.number_from);
  DivergenceWatch watch(name, ChipNumbering(options.number_from, chain.size()));
  auto check = [&](bool was) {
    if (!was && watch.diverged()) decoder.divergence(watch.first());
  };
  TraceEvent e;
  std::vector<std::uint8_t> rx;
  double previous = 0;  // display time of the end of the event before (a frame's CS rising edge)
  TraceWire shown_wire;  // the host's wire settings as the log last said them
  while (in.next(e)) {
    const bool diverged = watch.diverged();
    if (e.kind == TraceEventKind::frame) {
      if (e.wire.known ? !shown_wire.known || !e.wire.same_as(shown_wire) : shown_wire.known) {
        decoder.host_wire(display_seconds(e.tick, e.source_time), e.wire);
        shown_wire = e.wire;
      }
      previous = display_seconds(e.end(), e.source_time == e.source_time
                                              ? e.source_time + static_cast<double>(e.duration) / kTicksPerSecond
                                              : e.source_time);
      ++decoder.summary.frames;
      rx.resize(e.mosi.size());
      tracker.begin_frame(e, rx);
      watch.frame(e, rx);
      check(diverged);
      tracker.end_frame();
      // Lines of this time stay queued: a later event of the same time may add lines of
      // chips numbered lower, which come first.
      decoder.flush(std::min(tracker.pending_answer_seconds(), display_seconds(e.tick, e.source_time)));
      continue;
    }
    if (e.chip >= chain.size())
      throw TraceError(name, e.line, trace_chip_outside_chain(e.chip, chain.size()));
    const bool output = e.is_observation();
    // Where the emulated output took the observed level: a copy of the chip before the event,
    // searched up to the observation's tick.
    Tick edge = kNever;
    if (output && chain.now() <= e.tick) {
      Chip probe = chain.chip(e.chip);
      probe.set_diagnostic_sink({});
      const auto level_at = [&](Tick tick) {
        Chip c = probe;
        c.advance_to(tick);
        return observed_level(c, e.pin) == (e.value != 0);
      };
      if (level_at(probe.now())) {
        edge = probe.now();  // it changed with the event before (a frame's CS rising edge)
      } else if (level_at(e.tick)) {
        Tick lo = probe.now(), hi = e.tick;  // not at lo, at hi
        while (hi - lo > 1) {
          const Tick mid = lo + (hi - lo) / 2;
          (level_at(mid) ? hi : lo) = mid;
        }
        edge = hi;
      }
    }
    tracker.apply(e);
    const double t = display_seconds(e.tick, e.source_time);
    if (e.kind == TraceEventKind::advance) continue;  // time only
    if (e.is_observation()) {
      const Chip& chip = chain.chip(e.chip);
      watch.observation(e, observed_level(chip, e.pin));
      check(diverged);
    }
    if (output && edge != kNever) {
      const double before = static_cast<double>(e.tick - edge) / static_cast<double>(kTicksPerSecond);
      decoder.pin(e, t, previous, t - before, edge == e.tick);
    } else {
      decoder.pin(e, t, previous);
    }
    // Outputs looked at together share one bound; an input or fault is an event of its own.
    if (!e.is_observation()) previous = t;
    decoder.flush(std::min(tracker.pending_answer_seconds(), t));
  }
  tracker.finish();
  decoder.flush(std::numeric_limits<double>::infinity());
  decoder.summary.divergence = watch.first();
  decoder.summary.frames_diverged = watch.frames_diverged();
  decoder.summary.pins_diverged = watch.pins_diverged();
  return decoder.summary;
}

}  // namespace l6470emu
