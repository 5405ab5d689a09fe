// replay_trace: the frame loop (ProtocolTracker without an observer, so a frame costs a
// chain frame and a comparison) and the divergence reports, built only when needed.
#include "daisychain/replay.hpp"

#include <cstdio>
#include <vector>

#include "daisychain/divergence.hpp"
#include "daisychain/explain.hpp"
#include "daisychain/protocol_tracker.hpp"

namespace l6470emu {
namespace {

std::string time_text(Tick tick, double source_time) {
  char buf[80];
  if (source_time == source_time)
    std::snprintf(buf, sizeof buf, "t=%.9f s", source_time);
  else
    std::snprintf(buf, sizeof buf, "t=%s s", format_seconds(tick).c_str());
  return buf;
}

std::string where(const std::string& name, const TraceEvent& e) {
  std::string w = e.line ? name + ":" + std::to_string(e.line) : name;
  if (e.repetition) w += " (repetition " + std::to_string(e.repetition) + ")";
  return w;
}

std::string indent(const std::string& text, const char* prefix) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    std::size_t j = text.find('\n', i);
    if (j == std::string::npos) j = text.size();
    out += prefix;
    out.append(text, i, j - i);
    out += '\n';
    i = j + 1;
  }
  return out;
}

constexpr std::size_t kMaxChipLines = 16;  // chips listed in a report before cutting short
constexpr std::size_t kMaxDumps = 4;       // chip state dumps per report

class Replayer {
 public:
  Replayer(TraceReader& in, Chain& chain, const ReplayOptions& options,
           const std::function<void(const Divergence&)>& on_divergence)
      : in_(in), chain_(chain), options_(options), on_divergence_(on_divergence), tracker_(chain, {}, options.number_from),
        name_(in.header().name) {}

  ReplayResult run() {
    TraceEvent e;
    const std::size_t n = chain_.size();
    while (in_.next(e)) {
      if (e.kind == TraceEventKind::frame) {
        ++result_.frames;
        const std::size_t len = e.mosi.size();
        rx_.resize(len);
        tracker_.begin_frame(e, rx_);
        if (e.miso.empty()) {
          result_.bytes_unknown += len;
        } else {
          bool differs = false;
          for (std::size_t i = 0; i < len; ++i) {
            if (!e.miso_byte_known(i)) {
              ++result_.bytes_unknown;
              continue;
            }
            ++result_.bytes_compared;
            differs = differs || e.miso[i] != rx_[i];
          }
          if (differs) {
            ++result_.divergent_frames;
            if (wants_report()) record(frame_report(e, n));
          }
        }
        tracker_.end_frame();
        if (stop()) break;
        continue;
      }
      if (e.chip >= n)
        throw TraceError(name_, e.line, trace_chip_outside_chain(e.chip, n));
      if (e.is_observation()) {
        if (!options_.compare_pins) continue;
        chain_.advance_to(e.tick);
        const Chip& chip = chain_.chip(e.chip);
        const bool level = observed_level(chip, e.pin);
        ++result_.pin_checks;
        if (level != (e.value != 0)) {
          ++result_.pin_mismatches;
          if (wants_report()) record(pin_report(e, level));
          if (stop()) break;
        }
        continue;
      }
      tracker_.apply(e);
    }
    return std::move(result_);
  }

 private:
  bool wants_report() const { return options_.max_reports == 0 || result_.divergences.size() < options_.max_reports; }
  bool stop() {
    if (options_.keep_going || result_.matched()) return false;
    result_.stopped_early = true;
    return true;
  }
  void record(Divergence d) {
    if (on_divergence_) on_divergence_(d);
    result_.divergences.push_back(std::move(d));
  }

  Divergence frame_report(const TraceEvent& e, std::size_t n) {
    Divergence d;
    d.frame = result_.frames;
    d.line = e.line;
    d.tick = e.tick;
    d.source_time = display_seconds(e.tick, e.source_time);
    const std::size_t len = e.mosi.size();
    std::vector<std::size_t> bad;
    for (std::size_t i = 0; i < len; ++i)
      if (e.miso_byte_known(i) && e.miso[i] != rx_[i]) bad.push_back(i);

    d.summary = where(name_, e) + ": frame " + std::to_string(d.frame) + " at " + time_text(e.tick, e.source_time) +
                ": MISO byte " + std::to_string(bad[0]) + " expected " + hex_value(e.miso[bad[0]], 8) + ", emulated " +
                hex_value(rx_[bad[0]], 8);
    if (bad.size() > 1) d.summary += " (and " + std::to_string(bad.size() - 1) + " more bytes differ)";

    std::string r = d.summary + "\n";
    r += "  MOSI      " + hex_bytes(e.mosi) + "\n";
    r += "  expected  " + hex_bytes(e.miso, e.miso_known) + "\n";
    r += "  emulated  " + hex_bytes(rx_) + "\n";
    std::string marks(len * 3, ' ');
    for (std::size_t i : bad) marks[i * 3] = marks[i * 3 + 1] = '^';
    while (!marks.empty() && marks.back() == ' ') marks.pop_back();
    r += "            " + marks + "\n";
    r += "  where the differing MISO bytes come from:\n";
    bool beyond_chain = false;
    for (std::size_t i : bad) {
      r += "    byte " + std::to_string(i) + ": " + tracker_.describe_miso(i) + "\n";
      beyond_chain = beyond_chain || i >= n;
    }
    if (beyond_chain)
      r += "    (the captured chain answered where " + std::to_string(n) +
           " emulated chips only pass MOSI back: is the real chain longer? see --chain)\n";
    r += "  what each chip decodes at this frame's CS rising edge:\n";
    // In the order the user counts the chips.
    const ChipNumbering& numbering = tracker_.numbering();
    for (std::size_t u = 0; u < n && u < kMaxChipLines; ++u)
      r += "    " + tracker_.describe_decode(numbering.index_of(u)) + "\n";
    if (n > kMaxChipLines) r += "    ... (" + std::to_string(n - kMaxChipLines) + " more chips)\n";
    std::size_t dumps = 0;
    for (std::size_t i : bad) {
      if (i >= n || dumps == kMaxDumps) continue;
      ++dumps;
      r += "  " + numbering.label(i) + " state (emulated, as it answered):\n";
      r += indent(chain_.chip(i).dump(), "    ");
    }
    d.report = std::move(r);
    return d;
  }

  Divergence pin_report(const TraceEvent& e, bool emulated) {
    Divergence d;
    d.frame = result_.frames;
    d.line = e.line;
    d.tick = e.tick;
    d.source_time = display_seconds(e.tick, e.source_time);
    const TracePin pin = e.pin;
    auto level = [pin](bool l) {
      const char* meaning = pin == TracePin::BUSY ? (l ? " (released)" : " (busy)")
                            : pin == TracePin::FLAG ? (l ? " (no alarm)" : " (alarm)")
                                                    : (l ? " (switch open)" : " (switch closed)");
      return std::string(l ? "high" : "low") + meaning;
    };
    d.summary = where(name_, e) + ": " + time_text(e.tick, e.source_time) + " (after frame " +
                std::to_string(d.frame) + "): " + tracker_.numbering().label(e.chip) + " " + std::string(to_string(e.pin)) +
                (pin == TracePin::SW_AXIS ? " (driven by its axis)" : "") + " expected " + level(e.value != 0) + ", emulated " + level(emulated);
    d.report = d.summary + "\n  " + tracker_.numbering().label(e.chip) + " state (emulated):\n" +
               indent(chain_.chip(e.chip).dump(), "    ");
    return d;
  }

  TraceReader& in_;
  Chain& chain_;
  const ReplayOptions& options_;
  const std::function<void(const Divergence&)>& on_divergence_;
  ProtocolTracker tracker_;
  std::string name_;
  ReplayResult result_;
  std::vector<std::uint8_t> rx_;
};

}  // namespace

ReplayResult replay_trace(TraceReader& in, Chain& chain, const ReplayOptions& options,
                          const std::function<void(const Divergence&)>& on_divergence) {
  return Replayer(in, chain, options, on_divergence).run();
}

}  // namespace l6470emu
