// ProtocolTracker: reads each chip's shift register before the CS rising edge (the byte
// it decodes) and its decoder state before and after, and mirrors the answer rules of
// docs/chip-model.md "SPI framing": an answer's byte j is loaded at the j-th decode after
// its GetParam/GetStatus and leaves on MISO in the next frame, from the chip's slot.
#include "daisychain/protocol_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "core/axis_text.hpp"
#include "core/counted.hpp"
#include "daisychain/explain.hpp"

namespace l6470emu {
namespace {

std::string byte_hex(std::uint8_t b) { return hex_value(b, 8); }

std::string seconds_text(double s) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "t=%.6f s", s);
  return buf;
}

}  // namespace

double display_seconds(Tick tick, double source_time) {
  if (source_time == source_time) return source_time;
  return static_cast<double>(tick) / static_cast<double>(kTicksPerSecond);
}

ProtocolTracker::ProtocolTracker(Chain& chain, Observer observer, NumberFrom numbering)
    : chain_(chain), observer_(std::move(observer)), numbering_(numbering, chain.size()), chips_(chain.size()) {
  for (std::size_t k = 0; k < chain_.size(); ++k)
    chain_.chip(k).set_diagnostic_sink([this, k](const Diagnostic& d) { diagnostics_.push_back({k, d}); });
}

ProtocolTracker::~ProtocolTracker() {
  for (std::size_t k = 0; k < chain_.size(); ++k) chain_.chip(k).set_diagnostic_sink({});
}

ProtocolEvent ProtocolTracker::event_here(ProtocolEvent::Kind kind, std::size_t chip) const {
  ProtocolEvent e;
  e.kind = kind;
  e.chip = chip;
  e.frame = frame_no_;
  e.tick = frame_.tick;
  e.source_time = frame_.source_time;
  e.line = frame_.line;
  e.repetition = frame_.repetition;
  return e;
}

void ProtocolTracker::report(ProtocolEvent&& e) {
  if (observer_) observer_(e);
}

void ProtocolTracker::begin_frame(const TraceEvent& frame, std::span<std::uint8_t> rx) {
  frame_ = frame;
  chain_.advance_to(frame.tick);
  if (!frame.wire.known) {
    // A trace that does not say how the host drove the wire: SPI mode 3, byte by byte.
    chain_.select();
    chain_.exchange(frame.mosi, rx);
  } else {
    // As the recording's host: its mode and bit order at bit level, and (timed CS edges) a
    // deselect shorter than t_disCS leaving the chips' answers unloaded.
    if (frame.wire.deselect_timed)
      chain_.select_wire();
    else
      chain_.select();
    chain_.exchange_wire(frame.mosi, rx, frame.wire.settings());
  }
  const std::size_t n = chain_.size(), len = frame.mosi.size();
  for (std::size_t k = 0; k < n; ++k) {
    ChipTrack& c = chips_[k];
    Answer& a = c.answer;
    const bool hears = chain_.hears_frame(k);
    if (a.active && k < len && hears) {
      // The answer byte in chip k's register left on MISO byte k.
      const unsigned shift = 8u * (a.len - 1u - a.loaded);
      a.seen = static_cast<std::uint8_t>(a.seen | (1u << a.loaded));
      a.emulated |= std::uint32_t{rx[k]} << shift;
      if (frame.miso_byte_known(k)) {
        a.known = static_cast<std::uint8_t>(a.known | (1u << a.loaded));
        a.captured |= std::uint32_t{frame.miso[k]} << shift;
      }
    }
    const Chip& chip = chain_.chip(k);
    c.enabled = hears;
    c.lost = hears != chip.spi_enabled();  // not in standby: missing this frame (a lost frame)
    c.was_collecting = chip.collecting_arguments();
    c.table = &chip.registers();
    c.byte = chain_.shift_register(k);
  }
}

void ProtocolTracker::finish_answer(std::size_t k, AnswerEnd why) {
  Answer& a = chips_[k].answer;
  a.active = false;
  if (!observer_) return;
  const std::uint8_t all = static_cast<std::uint8_t>((1u << a.len) - 1u);
  ProtocolEvent e;
  e.kind = ProtocolEvent::Kind::answer;
  e.chip = k;
  e.frame = a.frame;
  e.tick = a.tick;
  e.source_time = a.source_time;
  e.line = a.line;
  e.repetition = a.repetition;
  e.opcode = a.opcode;
  e.op = a.table->opcodes[a.opcode];
  e.reg = a.reg;
  e.table = a.table;
  e.layout = &chain_.chip(k).status_layout();
  e.answer_bytes = a.len;
  e.complete = a.seen == all;
  e.captured = a.known == all;
  // Bytes not captured are taken from the emulator.
  std::uint32_t value = 0;
  for (unsigned j = 0; j < a.len; ++j) {
    const unsigned shift = 8u * (a.len - 1u - j);
    const std::uint32_t byte_mask = 0xFFu << shift;
    value |= ((a.known >> j) & 1u) ? (a.captured & byte_mask) : (a.emulated & byte_mask);
  }
  e.value = value;
  e.emulated = a.emulated;
  if (!e.complete) {
    e.issue = ProtocolEvent::Issue::answer_lost;
    unsigned got = 0;
    for (unsigned j = 0; j < a.len; ++j) got += (a.seen >> j) & 1u;
    e.text = "only " + std::to_string(got) + " of " + std::to_string(a.len) + " answer bytes reached MISO";
    switch (why) {
      case AnswerEnd::replaced: e.text += " (a new GetParam/GetStatus or a reset replaced the answer)"; break;
      case AnswerEnd::shifted_out: e.text += " (frames too short to clock them out)"; break;
      case AnswerEnd::trace_end: e.text += " (the trace ends before the rest)"; break;
    }
  }
  report(std::move(e));
}

std::optional<std::size_t> mosi_byte_decoded_by(std::size_t frame_len, std::size_t chain_len, std::size_t chip) {
  if (frame_len >= chain_len) return frame_len - chain_len + chip;
  if (chip >= chain_len - frame_len) return chip - (chain_len - frame_len);
  return std::nullopt;
}

std::string ProtocolTracker::host_byte_for(std::size_t k) const {
  const auto b = mosi_byte_decoded_by(frame_.mosi.size(), chain_.size(), k);
  return b ? byte_hex(frame_.mosi[*b]) : "its byte";
}

std::string ProtocolTracker::chip_range(std::size_t first, std::size_t last) const {
  std::size_t lo = numbering_.number_of(first), hi = numbering_.number_of(last);
  if (lo > hi) std::swap(lo, hi);
  return "chips " + std::to_string(lo) + ".." + std::to_string(hi);
}

std::string ProtocolTracker::origin_of(std::size_t k) const {
  const std::size_t len = frame_.mosi.size();
  if (const auto b = mosi_byte_decoded_by(len, chain_.size(), k)) return "MOSI byte " + std::to_string(*b);
  return "the byte " + numbering_.label(k + len) + " left in the chain";
}

void ProtocolTracker::end_frame() {
  chain_.advance_to(frame_.end());
  diagnostics_.clear();
  if (frame_.wire.known)
    chain_.deselect_wire();  // each chip's SDO latch kept for the next frame
  else
    chain_.deselect();
  const std::size_t n = chain_.size(), len = frame_.mosi.size();
  if (len > 0) {
    for (std::size_t k = 0; k < n; ++k) {
      ChipTrack& c = chips_[k];
      if (!c.enabled) {
        if (observer_) {
          ProtocolEvent e = event_here(ProtocolEvent::Kind::diagnostic, k);
          e.issue = ProtocolEvent::Issue::standby;
          e.text = (c.lost ? "misses this frame (a lost frame: as if its CS stayed high): ignores "
                           : "in standby (STBY\\RST low): ignores ") + host_byte_for(k);
          report(std::move(e));
        }
        continue;
      }
      const Chip& chip = chain_.chip(k);
      const bool now_collecting = chip.collecting_arguments();
      const Diagnostic* wrong = nullptr;
      const Diagnostic* notperf = nullptr;
      for (const PendingDiagnostic& p : diagnostics_) {
        if (p.chip != k) continue;
        if (p.d.kind == DiagnosticKind::wrong_cmd) wrong = &p.d;
        if (p.d.kind == DiagnosticKind::notperf_cmd) notperf = &p.d;
      }
      bool complete = false, new_answer = false, reset = false;
      std::uint8_t opcode = 0;
      std::uint32_t arg = 0;
      const Variant* table = c.table;
      if (!c.was_collecting) {
        opcode = c.byte;
        const Opcode& op = table->opcodes[opcode];
        if (wrong != nullptr) {
          if (observer_) {
            ProtocolEvent e = event_here(ProtocolEvent::Kind::diagnostic, k);
            e.issue = ProtocolEvent::Issue::wrong_cmd;
            e.opcode = opcode;
            e.table = table;
            e.text = "WRONG_CMD: " + opcode_name(opcode, *table) + " (" + wrong->message + ")";
            if (len < n && k < n - len) e.text += "; it is " + origin_of(k) + ", not a host byte";
            report(std::move(e));
          }
        } else if (now_collecting) {
          c.collect = {true, opcode, op, table, 0, 0, frame_no_};
        } else {
          complete = true;
        }
      } else {
        Collect& col = c.collect;
        col.arg = col.arg << 8 | c.byte;
        ++col.seen;
        if (!now_collecting) {
          complete = true;
          opcode = col.opcode;
          arg = col.arg;
          table = col.table;
          col.active = false;
        }
      }
      if (complete) {
        const Opcode& op = table->opcodes[opcode];
        new_answer = op.command == Command::GetParam || op.command == Command::GetStatus;
        reset = op.command == Command::ResetDevice && notperf == nullptr;
        if (observer_) {
          ProtocolEvent e = event_here(ProtocolEvent::Kind::command, k);
          e.opcode = opcode;
          e.op = op;
          e.arg = arg;
          e.table = table;
          e.layout = &chip.status_layout();
          if (op.command == Command::SetParam || op.command == Command::GetParam) e.reg = table->at_address(op.param);
          report(std::move(e));
          if (notperf != nullptr) {
            ProtocolEvent d = event_here(ProtocolEvent::Kind::diagnostic, k);
            d.issue = ProtocolEvent::Issue::notperf_cmd;
            d.opcode = opcode;
            d.table = table;
            d.text = "NOTPERF_CMD: " + opcode_name(opcode, *table) + " refused (" + notperf->message + ")";
            report(std::move(d));
          }
        }
      }
      Answer& a = c.answer;
      if (new_answer) {
        if (a.active) finish_answer(k, AnswerEnd::replaced);
        const Opcode& op = table->opcodes[opcode];
        const RegisterInfo* r = op.command == Command::GetParam ? table->at_address(op.param) : nullptr;
        a = Answer{};
        a.active = true;
        a.opcode = opcode;
        a.reg = r;
        a.table = table;
        a.len = r != nullptr ? r->spi_bytes() : 2;
        a.frame = frame_no_;
        a.tick = frame_.tick;
        a.source_time = frame_.source_time;
        a.line = frame_.line;
        a.repetition = frame_.repetition;
      } else if (reset) {
        if (a.active) finish_answer(k, AnswerEnd::replaced);
      } else if (a.active && ++a.loaded == a.len) {
        finish_answer(k, AnswerEnd::shifted_out);
      }
    }
    if (len != n && observer_) {
      ProtocolEvent e = event_here(ProtocolEvent::Kind::diagnostic, ProtocolEvent::kNoChip);
      e.issue = ProtocolEvent::Issue::chain_length;
      if (n == 1) {
        e.text = "CS held low over " + std::to_string(len) + " bytes for a single chip: only the last one (" +
                 byte_hex(frame_.mosi[len - 1]) + ") is decoded, the others pass through (a real chip needs CS raised after every byte)";
      } else if (len > n) {
        e.text = std::to_string(len) + " bytes for a chain of " + std::to_string(n) + ": MOSI bytes 0.." +
                 std::to_string(len - n - 1) + " pass through the chain undecoded; chip k decodes MOSI byte " +
                 (numbering_.from() == NumberFrom::miso ? std::to_string(len - n) + "+k" : std::to_string(len - 1) + "-k");
      } else {
        e.text = counted(len, "byte") + " for a chain of " + std::to_string(n) + ": " +
                 (n - len == 1 ? numbering_.label(0) + " decodes a byte" : chip_range(0, n - len - 1) + " decode bytes") +
                 " left in the chain, not host bytes (" + numbering_.label(0) + " decodes " + byte_hex(chips_[0].byte) + ", " +
                 origin_of(0) + ")";
      }
      report(std::move(e));
    }
  }
  ++frame_no_;
}

void ProtocolTracker::apply(const TraceEvent& e) {
  if (e.kind == TraceEventKind::frame) return;
  chain_.advance_to(e.tick);
  if (e.chip >= chain_.size()) return;  // the caller reports chips outside the chain
  Chip& chip = chain_.chip(e.chip);
  ChipTrack& c = chips_[e.chip];
  if (e.kind == TraceEventKind::advance) return;  // time only: the chain is there now
  if (e.kind == TraceEventKind::load) {
    chip.set_axis_load(e.load);
    return;
  }
  if (e.kind == TraceEventKind::axis) {
    if (e.text == "none") {
      chip.detach_axis();
      return;
    }
    AxisSpec spec;
    if (parse_axis_spec(e.text, spec).empty()) chip.attach_axis(spec);  // readers check the text
    return;
  }
  if (e.kind == TraceEventKind::stops) {
    chip.set_axis_stops(e.has_lower_stop, e.lower_stop, e.has_upper_stop, e.upper_stop);
    return;
  }
  if (e.kind == TraceEventKind::supply) {
    chip.set_axis_supply(e.supply_mV);
    return;
  }
  if (e.kind == TraceEventKind::pin) {
    switch (e.pin) {
      case TracePin::SW: chip.set_sw_pin(e.value != 0); break;
      case TracePin::STCK: chip.set_stck_pin(e.value != 0); break;
      case TracePin::DIR: chip.set_dir_pin(e.value != 0); break;
      case TracePin::STBY:
        if ((e.value != 0) != chip.spi_enabled()) {
          chip.set_stby_rst_pin(e.value != 0);
          // Standby resets the logic: no command, no answer.
          if (c.answer.active) finish_answer(e.chip, AnswerEnd::replaced);
          c.collect.active = false;
        }
        break;
      case TracePin::BUSY:
      case TracePin::FLAG:
      case TracePin::SW_AXIS: break;  // observations, compared by replay
    }
    return;
  }
  switch (e.fault) {
    case TraceFault::UVLO: chip.set_undervoltage(e.value != 0); break;
    case TraceFault::UVLO_ADC: chip.set_adc_undervoltage(e.value != 0); break;
    case TraceFault::OCD: chip.set_overcurrent(e.value != 0); break;
    case TraceFault::STALL_A: chip.set_stall(Bridge::A, e.value != 0); break;
    case TraceFault::STALL_B: chip.set_stall(Bridge::B, e.value != 0); break;
    case TraceFault::THERMAL: chip.set_thermal(static_cast<Thermal>(e.value & 3u)); break;
    case TraceFault::ADCIN: chip.set_adc_input(e.value); break;
    case TraceFault::POWER_CYCLE:
      chain_.power_cycle(e.chip);  // (between frames: at once)
      // A power cycle resets the logic: no command, no answer.
      if (c.answer.active) finish_answer(e.chip, AnswerEnd::replaced);
      c.collect.active = false;
      break;
    case TraceFault::MISO_FLIP: chain_.arm_miso_flip(e.chip, e.value & 7u); break;
    case TraceFault::LOST_FRAME: chain_.arm_lost_frame(e.chip); break;
  }
}

double ProtocolTracker::pending_answer_seconds() const {
  double t = std::numeric_limits<double>::infinity();
  for (const ChipTrack& c : chips_)
    if (c.answer.active) t = std::min(t, display_seconds(c.answer.tick, c.answer.source_time));
  return t;
}

void ProtocolTracker::finish() {
  for (std::size_t k = 0; k < chips_.size(); ++k)
    if (chips_[k].answer.active) finish_answer(k, AnswerEnd::trace_end);
}

std::string ProtocolTracker::describe_miso(std::size_t i) const {
  const std::size_t n = chain_.size();
  if (i >= n) return "MOSI byte " + std::to_string(i - n) + " coming back through the chain (frame longer than the chain)";
  const ChipTrack& c = chips_[i];
  const Answer& a = c.answer;
  if (!c.enabled) return numbering_.label(i) + (c.lost ? ": misses this frame (lost frame), drives 0x00" : ": in standby, drives 0x00");
  if (!a.active) return numbering_.label(i) + ": no answer pending (0x00)";
  return numbering_.label(i) + ": byte " + std::to_string(a.loaded + 1) + " of " + std::to_string(a.len) +
         " of the " + opcode_name(a.opcode, *a.table) + " answer (decoded in frame " + std::to_string(a.frame + 1) +
         ", " + seconds_text(display_seconds(a.tick, a.source_time)) + ")";
}

std::string ProtocolTracker::describe_decode(std::size_t k) const {
  const ChipTrack& c = chips_[k];
  std::string s = numbering_.label(k) + ": ";
  if (!c.enabled) return s + (c.lost ? "misses this frame (lost frame), ignores " : "in standby, ignores ") + byte_hex(c.byte);
  if (c.was_collecting) {
    const Collect& col = c.collect;
    return s + "argument byte " + std::to_string(col.seen + 1) + " of " + std::to_string(col.op.arg_bytes) + " of " +
           opcode_name(col.opcode, *col.table) + " = " + byte_hex(c.byte);
  }
  return s + "decodes " + byte_hex(c.byte) + " = " + opcode_name(c.byte, *c.table);
}

}  // namespace l6470emu
