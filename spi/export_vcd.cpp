// VCD writing: declarations grouped by scope, $dumpvars with the initial values, then
// "#time" blocks of changes. SPI frames are drawn bit by bit in mode 3.
#include "spi/export_vcd.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <memory>
#include <optional>
#include <ios>
#include <ostream>
#include <stdexcept>

namespace l6470emu {

// ---------------------------------------------------------------- VcdWriter

VcdWriter::VcdWriter(std::ostream& out, unsigned timescale_ns) : out_(out), timescale_(timescale_ns) {
  if (timescale_ns != 1 && timescale_ns != 10 && timescale_ns != 100)
    throw std::invalid_argument("VCD timescale must be 1, 10 or 100 ns");
}

namespace {

/// VCD identifier codes: printable ASCII '!'..'~', base 94.
std::string vcd_id(std::size_t n) {
  std::string id;
  do {
    id += static_cast<char>('!' + n % 94);
    n /= 94;
  } while (n > 0);
  return id;
}

}  // namespace

int VcdWriter::wire(std::string_view scope, std::string_view name, bool initial) {
  if (begun_) throw std::logic_error("VCD signals must be declared before the first change");
  signals_.push_back({std::string(scope), std::string(name), vcd_id(signals_.size()), 1, initial ? 1 : 0});
  return static_cast<int>(signals_.size() - 1);
}

int VcdWriter::number(std::string_view scope, std::string_view name, std::int64_t initial) {
  if (begun_) throw std::logic_error("VCD signals must be declared before the first change");
  signals_.push_back({std::string(scope), std::string(name), vcd_id(signals_.size()), 64, initial});
  return static_cast<int>(signals_.size() - 1);
}

void VcdWriter::put_value(const Signal& s) {
  if (s.bits == 1) {
    buf_ += s.is_unknown ? 'x' : (s.value ? '1' : '0');
    buf_ += s.id;
    buf_ += '\n';
    return;
  }
  buf_ += 'r';
  buf_ += std::to_string(s.value);
  buf_ += ' ';
  buf_ += s.id;
  buf_ += '\n';
}

void VcdWriter::begin() {
  begun_ = true;
  buf_ = "$version l6470emu $end\n$timescale " + std::to_string(timescale_) + " ns $end\n";
  // Scopes in the order they were first used.
  std::vector<std::string> scopes;
  for (const Signal& s : signals_)
    if (std::find(scopes.begin(), scopes.end(), s.scope) == scopes.end()) scopes.push_back(s.scope);
  for (const std::string& scope : scopes) {
    buf_ += "$scope module " + scope + " $end\n";
    for (const Signal& s : signals_)
      if (s.scope == scope)
        buf_ += "$var " + std::string(s.bits == 1 ? "wire" : "real") + " " + std::to_string(s.bits) + " " + s.id +
                " " + s.name + " $end\n";
    buf_ += "$upscope $end\n";
  }
  buf_ += "$enddefinitions $end\n#0\n$dumpvars\n";
  for (const Signal& s : signals_) put_value(s);
  buf_ += "$end\n";
  time_written_ = true;
  spill();
}

void VcdWriter::at(std::uint64_t time_ns) {
  if (!begun_) begin();
  std::uint64_t units = time_ns / timescale_;
  if (units < last_units_) units = last_units_;  // never backwards
  if (units != last_units_ || !time_written_) {
    if (!buf_.empty()) spill();
    buf_ = '#';
    buf_ += std::to_string(units);
    buf_ += '\n';
    last_units_ = units;
    time_written_ = true;
  }
}

void VcdWriter::change(std::uint64_t time_ns, int signal, std::int64_t value) {
  Signal& s = signals_.at(static_cast<std::size_t>(signal));
  if (begun_ && !s.is_unknown && s.value == value) return;
  at(time_ns);
  s.value = value;
  s.is_unknown = false;
  put_value(s);
  if (buf_.size() >= kMaxBufferedBytes) spill();
}

void VcdWriter::unknown(std::uint64_t time_ns, int signal) {
  Signal& s = signals_.at(static_cast<std::size_t>(signal));
  if (begun_ && s.is_unknown) return;
  at(time_ns);
  s.is_unknown = true;
  put_value(s);
  if (buf_.size() >= kMaxBufferedBytes) spill();
}

void VcdWriter::spill() {
  out_ << buf_;
  buf_.clear();
  check_output();
}

void VcdWriter::check_output() const {
  if (!out_) throw std::ios_base::failure("VCD output: write failed");
}

void VcdWriter::finish(std::uint64_t time_ns) {
  at(time_ns);
  out_ << buf_;
  buf_.clear();
  const std::uint64_t units = std::max(last_units_, time_ns / timescale_);
  if (units != last_units_) out_ << "#" << units << "\n";
  out_.flush();
}

// ---------------------------------------------------------------- SPI wires

SpiVcdWaveform::SpiVcdWaveform(VcdWriter& w, std::string_view scope)
    : w_(w),
      cs_(w.wire(scope, "CS", true)),
      sck_(w.wire(scope, "SCK", true)),
      mosi_(w.wire(scope, "MOSI", false)),
      miso_(w.wire(scope, "MISO", false)) {}

std::uint64_t SpiVcdWaveform::draw(const TraceEvent& frame, std::uint64_t limit_ns) {
  const std::uint64_t unit = w_.timescale_ns();
  std::uint64_t t0 = std::max(ns_from_ticks(frame.tick), w_.last_time_ns() + unit);
  t0 = (t0 + unit - 1) / unit * unit;
  const std::uint64_t bits = frame.mosi.size() * 8;
  const std::uint64_t slots = 2 * bits + 2;  // half periods: lead-in, 2 per bit, lead-out
  std::uint64_t half = 100;                  // 5 MHz when the capture has no duration
  if (frame.duration > 0) half = ns_from_ticks(frame.duration) / slots;
  if (limit_ns > t0 && t0 + half * slots > limit_ns) half = (limit_ns - t0) / slots;
  half = std::max<std::uint64_t>(half / unit * unit, unit);

  w_.change(t0, cs_, 0);
  std::uint64_t t = t0 + half;
  for (std::size_t i = 0; i < frame.mosi.size(); ++i) {
    const bool known = frame.miso_byte_known(i);
    for (int b = 7; b >= 0; --b) {
      w_.change(t, sck_, 0);
      w_.change(t, mosi_, (frame.mosi[i] >> b) & 1);
      if (known)
        w_.change(t, miso_, (frame.miso[i] >> b) & 1);
      else
        w_.unknown(t, miso_);
      t += half;
      w_.change(t, sck_, 1);
      t += half;
    }
  }
  const std::uint64_t end = std::max(t, ns_from_ticks(frame.end()));
  w_.change(end, cs_, 1);
  return end;
}

// ---------------------------------------------------------------- export

namespace {

/// The wire a pin event is drawn on: SW whether the host or the axis drove it.
TracePin vcd_pin(TracePin pin) { return pin == TracePin::SW_AXIS ? TracePin::SW : pin; }

}  // namespace

NextFrameTicks::NextFrameTicks(std::unique_ptr<TraceReader> pass) : pass_(std::move(pass)) {
  TraceEvent e;
  while (pass_->next(e))
    if (e.kind == TraceEventKind::frame) return;
  done_ = true;
}

std::optional<Tick> NextFrameTicks::after_frame() {
  TraceEvent e;
  while (!done_ && pass_->next(e))
    if (e.kind == TraceEventKind::frame) return e.tick;
  done_ = true;
  return std::nullopt;
}

void export_vcd(const TracePasses& passes, std::ostream& out, const VcdOptions& options) {
  VcdWriter w(out, options.timescale_ns);
  SpiVcdWaveform spi(w);
  // One wire per (chip, pin) that occurs, with the level of its first event as the initial one.
  std::map<std::pair<std::uint16_t, TracePin>, int> pins;
  {
    std::unique_ptr<TraceReader> first = passes();
    TraceEvent e;
    while (first->next(e))
      if (e.kind == TraceEventKind::pin) pins.emplace(std::make_pair(e.chip, vcd_pin(e.pin)), -1);
  }
  for (auto& [key, id] : pins) {
    // Inputs idle high except STCK; outputs default to released.
    id = w.wire("chip" + std::to_string(key.first), to_string(key.second), key.second != TracePin::STCK);
  }
  std::unique_ptr<TraceReader> events = passes();
  NextFrameTicks next(passes());
  std::uint64_t end = 0;
  TraceEvent e;
  while (events->next(e)) {
    if (e.kind == TraceEventKind::frame) {
      const std::optional<Tick> limit = next.after_frame();
      end = std::max(end, spi.draw(e, limit ? ns_from_ticks(*limit) : 0));
    } else if (e.kind == TraceEventKind::pin) {
      const std::uint64_t t = ns_from_ticks(e.tick);
      w.change(t, pins[{e.chip, vcd_pin(e.pin)}], e.value);
      end = std::max(end, t);
    }
  }
  w.finish(end + 1000);
}

void export_vcd(const Trace& trace, std::ostream& out, const VcdOptions& options) {
  export_vcd([&trace] { return trace.reader(); }, out, options);
}

}  // namespace l6470emu
