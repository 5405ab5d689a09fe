// make_report_chain: five passes over a chain's trace, each through a fresh chain of the world:
// its end, the motion series (sample_motion), the frames and the chips' state (ProtocolTracker,
// DivergenceWatch), the sanitizer's rules (ChainChecker on the frames as the bus gives them) and
// the divergences (replay_trace). Each keeps within ReportLimits as it goes. make_report_data:
// the chains of a run, the limits shared among them (share_limits).
#include "tools/report_data.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <tuple>

#include "board/board_chain.hpp"
#include "board/coverage_report.hpp"
#include "board/sanitizer.hpp"
#include "core/counted.hpp"
#include "core/status.hpp"
#include "daisychain/divergence.hpp"
#include "daisychain/explain.hpp"
#include "daisychain/phase_drive.hpp"
#include "daisychain/protocol_tracker.hpp"
#include "daisychain/replay.hpp"

namespace l6470emu {
namespace {

std::string hex_bytes(std::span<const std::uint8_t> bytes, const TraceEvent* known_of = nullptr) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string s;
  s.reserve(bytes.size() * 3);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i) s += ' ';
    if (known_of != nullptr && !known_of->miso_byte_known(i)) {
      s += "??";
      continue;
    }
    s += kHex[bytes[i] >> 4];
    s += kHex[bytes[i] & 15];
  }
  return s;
}

bool live_register(Reg id) { return id == Reg::ABS_POS || id == Reg::EL_POS || id == Reg::SPEED || id == Reg::STATUS; }

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

std::vector<StatusField> status_fields(const StatusLayout& l) {
  std::vector<StatusField> f;
  auto add = [&](std::string name, std::int8_t bit, unsigned width, bool low) {
    if (bit >= 0) f.push_back({std::move(name), static_cast<unsigned>(bit), width, low});
  };
  add("HiZ", l.hiz, 1, false);
  add("BUSY", l.busy, 1, true);
  add("SW_F", l.sw_f, 1, false);
  add("SW_EVN", l.sw_evn, 1, false);
  add("DIR", l.dir, 1, false);
  add("MOT_STATUS", l.mot_status, 2, false);
  if (l.notperf_cmd == l.wrong_cmd) {
    add("CMD_ERROR", l.wrong_cmd, 1, false);
  } else {
    add("NOTPERF_CMD", l.notperf_cmd, 1, false);
    add("WRONG_CMD", l.wrong_cmd, 1, false);
  }
  add("UVLO", l.uvlo, 1, true);
  add("UVLO_ADC", l.uvlo_adc, 1, true);
  add("TH_WRN", l.th_wrn, 1, true);
  add("TH_SD", l.th_sd, 1, true);
  add("TH_STATUS", l.th_status, 2, false);
  add("OCD", l.ocd, 1, true);
  add(std::string(l.step_loss_a_name), l.step_loss_a, 1, true);
  add(std::string(l.step_loss_b_name), l.step_loss_b, 1, true);
  add("SCK_MOD", l.sck_mod, 1, false);
  std::sort(f.begin(), f.end(), [](const StatusField& a, const StatusField& b) { return a.bit < b.bit; });
  return f;
}

/// Keeps at most `max_points` of a time series: per time slice of [from, to] its first and
/// last sample and those `keep` marks (extremes, first changes), as sample_motion thins.
template <typename Sample, typename Keep>
void thin(std::vector<Sample>& v, Tick from, Tick to, std::size_t max_points, std::size_t kept_per_slice, Keep keep) {
  if (v.size() <= max_points) return;
  const std::size_t slices = std::max<std::size_t>(1, max_points / kept_per_slice);
  const Tick span = std::max<Tick>(1, to - from);
  auto slice_of = [&](Tick t) {
    const Tick into = t > from ? t - from : 0;
    return std::min<std::size_t>(slices - 1, static_cast<std::size_t>(static_cast<unsigned __int128>(into) * slices / span));
  };
  std::vector<Sample> out;
  out.reserve(max_points);
  std::vector<std::size_t> marks;
  for (std::size_t i = 0; i < v.size();) {
    const std::size_t slice = slice_of(v[i].tick);
    std::size_t j = i;
    while (j < v.size() && slice_of(v[j].tick) == slice) ++j;
    marks.assign({i, j - 1});
    keep(v, i, j, marks);
    std::sort(marks.begin(), marks.end());
    marks.erase(std::unique(marks.begin(), marks.end()), marks.end());
    for (std::size_t k : marks) out.push_back(v[k]);
    i = j;
  }
  v = std::move(out);
}

void thin_states(std::vector<StateSample>& v, Tick from, Tick to, std::size_t max_points) {
  thin(v, from, to, max_points, 8, [](const std::vector<StateSample>& s, std::size_t i, std::size_t j, std::vector<std::size_t>& m) {
    std::size_t lo_pos = i, hi_pos = i, lo_speed = i, hi_speed = i, status = 0;
    for (std::size_t k = i; k < j; ++k) {
      if (s[k].abs_pos < s[lo_pos].abs_pos) lo_pos = k;
      if (s[k].abs_pos > s[hi_pos].abs_pos) hi_pos = k;
      if (s[k].speed < s[lo_speed].speed) lo_speed = k;
      if (s[k].speed > s[hi_speed].speed) hi_speed = k;
      if (!status && s[k].status != s[i].status) status = k;
    }
    for (std::size_t k : {lo_pos, hi_pos, lo_speed, hi_speed, status})
      if (k) m.push_back(k);
  });
}

void thin_phase(std::vector<PhaseSample>& v, Tick from, Tick to, std::size_t max_points) {
  thin(v, from, to, max_points, 6, [](const std::vector<PhaseSample>& s, std::size_t i, std::size_t j, std::vector<std::size_t>& m) {
    std::size_t lo_a = i, hi_a = i, lo_b = i, hi_b = i;
    for (std::size_t k = i; k < j; ++k) {
      if (s[k].coil_a < s[lo_a].coil_a) lo_a = k;
      if (s[k].coil_a > s[hi_a].coil_a) hi_a = k;
      if (s[k].coil_b < s[lo_b].coil_b) lo_b = k;
      if (s[k].coil_b > s[hi_b].coil_b) hi_b = k;
    }
    m.insert(m.end(), {lo_a, hi_a, lo_b, hi_b});
  });
}

/// Rows collapsed into runs: when the last K rows (K <= 8) repeat the K before them, at the same
/// offsets, a run starts and goes on while the next rows repeat it at its period.
class Collapser {
 public:
  explicit Collapser(std::function<void(ReportEntry&&)> out) : out_(std::move(out)) {}

  void add(ReportRow&& r, std::uint64_t frame) {
    if (run_) {
      const ReportRow& want = run_->rows[partial_.size()];
      const Tick at = run_->tick + run_->repetitions * run_->period + want.tick;
      if (r.tick == at && same(r, want)) {
        partial_.push_back({std::move(r), frame});
        if (partial_.size() == run_->rows.size()) {
          ++run_->repetitions;
          partial_.clear();
        }
        return;
      }
      close_run();
    }
    tail_.push_back({std::move(r), frame});
    for (std::size_t k = 1; k <= kMaxGroup && 2 * k <= tail_.size(); ++k) {
      const std::size_t n = tail_.size();
      const Tick period = tail_[n - k].row.tick - tail_[n - 2 * k].row.tick;
      const Tick base = tail_[n - 2 * k].row.tick;
      bool repeats = period > 0 && tail_[n - 1].row.tick - tail_[n - k].row.tick + tail_[n - 1].row.duration < period;
      for (std::size_t i = 0; repeats && i < k; ++i) {
        const ReportRow& a = tail_[n - 2 * k + i].row;
        const ReportRow& b = tail_[n - k + i].row;
        repeats = b.tick - a.tick == period && same(a, b);
      }
      if (!repeats) continue;
      for (std::size_t i = 0; i + 2 * k < n; ++i) single(std::move(tail_[i]));
      ReportEntry e;
      e.tick = base;
      e.period = period;
      e.repetitions = 2;
      e.first_frame = tail_[n - 2 * k].frame;
      for (std::size_t i = 0; i < k; ++i) {
        ReportRow row = std::move(tail_[n - 2 * k + i].row);
        row.tick -= base;
        e.rows.push_back(std::move(row));
      }
      tail_.clear();
      run_ = std::move(e);
      return;
    }
    if (tail_.size() > 2 * kMaxGroup) {
      single(std::move(tail_.front()));
      tail_.pop_front();
    }
  }

  void finish() {
    if (run_) close_run();
    while (!tail_.empty()) {
      single(std::move(tail_.front()));
      tail_.pop_front();
    }
  }

 private:
  static constexpr std::size_t kMaxGroup = 8;
  struct Pending {
    ReportRow row;
    std::uint64_t frame;
  };
  static bool same(const ReportRow& a, const ReportRow& b) {
    return a.duration == b.duration && a.mosi == b.mosi && a.miso == b.miso && a.texts == b.texts &&
           a.diverged == b.diverged && a.diagnostic == b.diagnostic;
  }
  void single(Pending&& p) {
    ReportEntry e;
    e.tick = p.row.tick;
    e.first_frame = p.frame;
    p.row.tick = 0;
    e.rows.push_back(std::move(p.row));
    out_(std::move(e));
  }
  void close_run() {
    out_(std::move(*run_));
    run_.reset();
    for (Pending& p : partial_) tail_.push_back(std::move(p));
    partial_.clear();
  }

  std::function<void(ReportEntry&&)> out_;
  std::optional<ReportEntry> run_;
  std::vector<Pending> partial_;
  std::deque<Pending> tail_;
};

/// The time slices the timeline's row budget is shared over.
constexpr std::size_t kSlices = 1000;

std::size_t slice_of(Tick t, Tick end) {
  return std::min<std::size_t>(kSlices - 1, static_cast<std::size_t>(static_cast<unsigned __int128>(t) * kSlices / std::max<Tick>(end, 1)));
}

/// Each slice's share of `budget` rows when slice i has counts[i]: all of them up to a level
/// chosen so that the shares add up to the budget (slices with few rows keep them all; the
/// others share what is left equally).
std::vector<std::size_t> water_fill(const std::vector<std::size_t>& counts, std::size_t budget) {
  std::size_t lo = 0, hi = *std::max_element(counts.begin(), counts.end());
  auto total = [&](std::size_t level) {
    std::size_t n = 0;
    for (std::size_t c : counts) n += std::min(c, level);
    return n;
  };
  while (lo < hi) {  // the highest level whose total fits
    const std::size_t mid = lo + (hi - lo + 1) / 2;
    if (total(mid) <= budget)
      lo = mid;
    else
      hi = mid - 1;
  }
  std::vector<std::size_t> share(counts.size());
  for (std::size_t i = 0; i < counts.size(); ++i) share[i] = std::min(counts[i], lo);
  return share;
}

/// Keeps timeline entries within the row budget. Without shares it keeps everything (a trace
/// with fewer frames than the budget); with them (from a counting pass, water_fill) each time
/// slice keeps its first rows up to its share, and stands the rest as summarised spans, except
/// frames with commands, diagnostics or divergences, which have a reserve of their own. A
/// counting keeper only counts each slice's rows.
class Keeper {
 public:
  Keeper(ReportChain& data, std::size_t reserve, Tick end, const std::vector<std::size_t>* shares,
         std::vector<std::size_t>* counts)
      : data_(data), reserve_(reserve), end_(end), shares_(shares), counts_(counts) {}

  void add(ReportEntry&& e) {
    const std::size_t slice = slice_of(e.tick, end_);
    const std::size_t rows = e.rows.size();
    if (counts_) {
      (*counts_)[slice] += rows;
      return;
    }
    if (slice != slice_) {
      slice_ = slice;
      slice_kept_ = 0;
    }
    bool keep = shares_ == nullptr || slice_kept_ + rows <= (*shares_)[slice];
    if (keep) {
      slice_kept_ += rows;
    } else if (significant(e) && reserve_used_ + rows <= reserve_) {
      keep = true;
      reserve_used_ += rows;
    }
    if (keep) {
      close_gap();
      data_.entries.push_back(std::move(e));
      return;
    }
    data_.summarised = true;
    const Tick end = e.tick + (e.repetitions - 1) * e.period + e.rows.back().tick + e.rows.back().duration;
    if (!gap_) gap_ = ReportGap{e.tick, end, e.first_frame, 0, 0};
    gap_->to = std::max(gap_->to, end);
    gap_->frames += e.frames();
    for (const ReportRow& r : e.rows) gap_->commands += e.repetitions * commands(r);
  }

  void finish() { close_gap(); }

  /// Commands a row holds other than polls: texts that are not answers.
  static std::uint64_t commands(const ReportRow& r) {
    std::uint64_t n = 0;
    for (const std::string& t : r.texts)
      if (!t.empty() && t.find(" → ") == std::string::npos && t.rfind("Get", 0) != 0) ++n;
    return n;
  }

 private:
  static bool significant(const ReportEntry& e) {
    for (const ReportRow& r : e.rows)
      if (r.diverged || r.diagnostic || commands(r) > 0) return true;
    return false;
  }
  void close_gap() {
    if (gap_) data_.gaps.push_back(*gap_);
    gap_.reset();
  }

  ReportChain& data_;
  std::size_t reserve_, reserve_used_ = 0;
  Tick end_;
  const std::vector<std::size_t>* shares_;
  std::vector<std::size_t>* counts_;
  std::size_t slice_ = static_cast<std::size_t>(-1), slice_kept_ = 0;
  std::optional<ReportGap> gap_;
};

/// The main pass: frames, what each chip made of them, the chips' state after each.
class FramePass {
 public:
  /// `shares`: the timeline's row share of each time slice (nullptr: keep every row). With
  /// `counts`, the pass only counts each slice's rows (for water_fill) and extracts nothing else.
  FramePass(ReportChain& data, Chain& chain, const ReportOptions& o, const std::string& name, Tick end, Tick shown_to,
            const std::vector<std::size_t>* shares = nullptr, std::vector<std::size_t>* counts = nullptr)
      : data_(data),
        chain_(chain),
        options_(o),
        numbering_(o.number_from, chain.size()),
        watch_(name, numbering_),
        keeper_(data, o.limits.timeline_rows / 5, end, shares, counts),
        counting_(counts != nullptr),
        collapser_([this](ReportEntry&& e) { keeper_.add(std::move(e)); }),
        tracker_(chain, [this](const ProtocolEvent& e) { on_event(e); }, o.number_from),
        shown_to_(std::max(end, shown_to)) {
    const std::size_t n = chain.size();
    chips_.resize(n);
    seen_.resize(n);
    decoded_.assign(n, 0);
    state_budget_ = std::max<std::size_t>(64, o.limits.state_samples / n);
    phase_budget_ = std::max<std::size_t>(64, o.limits.phase_samples / n);
    register_budget_ = std::max<std::size_t>(64, o.limits.register_changes / n);
    input_budget_ = std::max<std::size_t>(64, o.limits.input_edges / n);
    step_ = std::max<Tick>({Tick{1}, o.phase_step, shown_to_ / std::max<std::size_t>(1, phase_budget_ / 2)});
    data_.phase_step = step_;
    for (std::size_t k = 0; k < n; ++k) {
      ReportChip& c = chips_[k];
      c.index = k;
      c.number = numbering_.number_of(k);
      const Chip& chip = chain.chip(k);
      c.variant = std::string(chip.variant().name);
      c.status_fields = status_fields(chip.status_layout());
      for (const RegisterInfo& r : chip.registers().registers)
        if (live_register(r.id)) c.live_registers.emplace_back(r.address, std::string(r.name));
      look_registers(k, 0);
      look_state(k, 0);
      look_phase(k, 0);
    }
  }

  void frame(const TraceEvent& e) {
    follow(e.tick);
    rx_.resize(e.mosi.size());
    ReportRow row;
    row.tick = e.tick;
    row.duration = e.duration;
    row.mosi = hex_bytes(e.mosi);
    if (!e.miso.empty()) row.miso = hex_bytes(e.miso, &e);
    row.texts.assign(chain_.size(), std::string());
    pending_.push_back({std::move(row), 0});
    const std::uint64_t before = watch_.frames_diverged();
    tracker_.begin_frame(e, rx_);
    watch_.frame(e, rx_);
    pending_.back().row.diverged = watch_.frames_diverged() != before;
    tracker_.end_frame();
    ++frames_;
    if (counting_) {
      release();
      return;
    }
    const Tick at = e.end();
    for (std::size_t k = 0; k < chain_.size(); ++k) {
      if (decoded_[k] == 2) look_registers(k, at);
      decoded_[k] = 0;
      look_state(k, at);
      look_phase(k, at);
    }
    release();
  }

  void other(const TraceEvent& e, const std::string& trace_name) {
    if (e.chip >= chain_.size()) throw TraceError(trace_name, e.line, trace_chip_outside_chain(e.chip, chain_.size()));
    follow(e.tick);
    tracker_.apply(e);
    if (e.kind == TraceEventKind::advance || counting_) return;
    ReportChip& c = chips_[e.chip];
    if (e.is_observation()) {
      watch_.observation(e, observed_level(chain_.chip(e.chip), e.pin));
      if (e.pin != TracePin::SW_AXIS) return;
    }
    if (e.kind == TraceEventKind::pin) {
      if (c.inputs.size() < input_budget_)
        c.inputs.push_back({e.tick, e.pin == TracePin::SW_AXIS ? "SW" : std::string(to_string(e.pin)), e.value != 0});
      else
        ++c.inputs_dropped;
    }
    if (e.kind != TraceEventKind::pin || e.pin != TracePin::STCK) stimulus(e);
    look_registers(e.chip, e.tick);
    look_state(e.chip, e.tick);
    look_phase(e.chip, e.tick);
    release();
  }

  void finish() {
    tracker_.finish();
    release();
    collapser_.finish();
    keeper_.finish();
    if (counting_) return;
    follow(shown_to_);
    for (std::size_t k = 0; k < chain_.size(); ++k) {
      look_state(k, chain_.now());
      look_phase(k, chain_.now());
      thinned_ = thinned_ || chips_[k].states.size() > state_budget_ || chips_[k].phase.size() > phase_budget_;
      thin_states(chips_[k].states, 0, shown_to_, state_budget_);
      thin_phase(chips_[k].phase, 0, shown_to_, phase_budget_);
    }
    if (thinned_) data_.summarised = true;
    data_.frames = frames_;
    data_.divergent_frames = watch_.frames_diverged();
    data_.divergent_pins = watch_.pins_diverged();
    if (watch_.diverged()) data_.first_divergence = watch_.first().summary;
    for (std::size_t u = 0; u < chips_.size(); ++u) data_.chips.push_back(std::move(chips_[numbering_.index_of(u)]));
  }

  std::vector<Finding> diagnostics;
  std::uint64_t diagnostics_count = 0;

 private:
  struct PendingRow {
    ReportRow row;
    int awaiting;  // answers of this frame not yet complete
  };

  void on_event(const ProtocolEvent& e) {
    const std::size_t at = static_cast<std::size_t>(e.frame - pending_base_);
    ReportRow* row = e.frame >= pending_base_ && at < pending_.size() ? &pending_[at].row : nullptr;
    switch (e.kind) {
      case ProtocolEvent::Kind::command: {
        const Command c = e.op.command;
        if (c == Command::GetParam || c == Command::GetStatus) {
          if (row) ++pending_[at].awaiting;
          decoded_[e.chip] = std::max<char>(decoded_[e.chip], 1);
          return;
        }
        if (c == Command::NOP) return;
        decoded_[e.chip] = 2;
        if (row) row->texts[e.chip] = describe_command(e.opcode, e.arg, *e.table, *e.layout);
        return;
      }
      case ProtocolEvent::Kind::answer: {
        std::string text;
        if (!e.complete) {
          text = opcode_name(e.opcode, *e.table) + " answer lost: " + e.text;
        } else {
          text = describe_answer(e.opcode, e.value, *e.table, *e.layout);
          if (!e.captured)
            text += "  (MISO not captured: the emulator's answer)";
          else if (e.value != e.emulated)
            text += "  (the emulator answers " + hex_value(e.emulated, 8u * e.answer_bytes) + ")";
        }
        if (row) {
          row->texts[e.chip] = std::move(text);
          --pending_[at].awaiting;
        }
        if (!e.complete) diagnostic(e, row);
        return;
      }
      case ProtocolEvent::Kind::diagnostic:
        diagnostic(e, row);
        return;
    }
  }

  void diagnostic(const ProtocolEvent& e, ReportRow* row) {
    ++diagnostics_count;
    if (row) row->diagnostic = true;
    if (diagnostics.size() >= options_.limits.findings) return;
    Finding f;
    f.kind = "diagnostic";
    f.name = issue_name(e.issue);
    f.frame = e.frame + 1;
    f.tick = e.tick;
    if (e.chip != ProtocolEvent::kNoChip) f.chip = numbering_.label(e.chip);
    f.text = e.text;
    diagnostics.push_back(std::move(f));
  }

  /// Rows whose answers are all in go on to the collapser, in frame order.
  void release() {
    while (!pending_.empty() && pending_.front().awaiting <= 0) {
      collapser_.add(std::move(pending_.front().row), pending_base_);
      pending_.pop_front();
      ++pending_base_;
    }
  }

  /// Lets the chain run up to `until`, looking at the phase drive of the chips that move.
  void follow(Tick until) {
    while (!counting_ && chain_.now() < until) {
      bool moving = false;
      for (std::size_t k = 0; k < chain_.size() && !moving; ++k) moving = motion_active(chain_.chip(k).motion());
      if (!moving) {
        chain_.advance_to(until);
        return;
      }
      const Tick t = std::min(until, chain_.now() + step_);
      chain_.advance_to(t);
      for (std::size_t k = 0; k < chain_.size(); ++k) look_phase(k, t);
    }
  }

  void look_state(std::size_t k, Tick t) {
    const Chip& chip = chain_.chip(k);
    const MotionState& m = chip.motion();
    StateSample s;
    s.tick = t;
    s.abs_pos = m.abs_pos;
    s.el_pos = m.el_pos;
    const auto speed = static_cast<std::int32_t>(chip.peek(Reg::SPEED));
    s.speed = m.dir ? speed : -speed;
    s.status = chip.status();
    std::vector<StateSample>& v = chips_[k].states;
    if (!v.empty()) {
      StateSample last = v.back();
      last.tick = t;
      if (last == s) return;
      if (v.back().tick == t) {
        v.back() = s;
        return;
      }
    }
    v.push_back(s);
    if (v.size() > 8 * state_budget_) {
      thin_states(v, 0, shown_to_, state_budget_);
      thinned_ = true;
    }
  }

  void look_phase(std::size_t k, Tick t) {
    const PhaseDrive d = phase_drive(chain_.chip(k));
    std::vector<PhaseSample>& v = chips_[k].phase;
    if (!v.empty() && v.back().coil_a == d.coil_a && v.back().coil_b == d.coil_b) return;
    if (!v.empty() && v.back().tick == t) {
      v.back().coil_a = d.coil_a;
      v.back().coil_b = d.coil_b;
      return;
    }
    v.push_back({t, d.coil_a, d.coil_b});
    if (v.size() > 8 * phase_budget_) {
      thin_phase(v, 0, shown_to_, phase_budget_);
      thinned_ = true;
    }
  }

  void look_registers(std::size_t k, Tick t) {
    const Chip& chip = chain_.chip(k);
    Seen& seen = seen_[k];
    const Variant& table = chip.registers();
    const bool new_table = seen.table != &table;
    for (const RegisterInfo& r : table.registers) {
      if (live_register(r.id)) continue;
      const std::uint32_t value = chip.peek_address(r.address);
      if (!new_table && seen.known[r.address] && seen.value[r.address] == value) continue;
      seen.known[r.address] = true;
      seen.value[r.address] = value;
      ReportChip& c = chips_[k];
      if (t != 0 && c.registers.size() >= register_budget_) {
        ++c.register_changes_dropped;
        data_.summarised = true;
        continue;
      }
      c.registers.push_back({t, r.address, std::string(r.name), value, describe_value(r, value, chip.status_layout())});
    }
    seen.table = &table;
  }

  void stimulus(const TraceEvent& e) {
    Stimulus s;
    s.tick = e.tick;
    s.frame = frames_;
    const bool level = e.value != 0;
    switch (e.kind) {
      case TraceEventKind::pin:
        if (e.pin == TracePin::STBY) {
          s.kind = "standby";
          s.text = level ? "STBY\\RST high (out of standby: power-up state)" : "STBY\\RST low (standby)";
        } else {
          s.kind = "switch";
          s.text = e.pin == TracePin::SW_AXIS ? (level ? "the axis's switch opened (SW high)" : "the axis's switch closed (SW low)")
                                              : (level ? "SW pin high (switch open)" : "SW pin low (switch closed)");
        }
        break;
      case TraceEventKind::fault:
        s.kind = "fault";
        if (e.fault == TraceFault::THERMAL) s.text = "THERMAL " + std::string(thermal_name(e.value));
        else if (e.fault == TraceFault::ADCIN) s.text = "ADCIN: ADC_OUT code " + std::to_string(e.value);
        else if (e.fault == TraceFault::POWER_CYCLE) s.text = "POWER_CYCLE: the chip is back as at power-up";
        else if (e.fault == TraceFault::MISO_FLIP) s.text = "MISO_FLIP: bit " + std::to_string(e.value & 7u) + " of the next frame's MISO byte";
        else if (e.fault == TraceFault::LOST_FRAME) s.text = "LOST_FRAME: the chip misses the next frame";
        else s.text = std::string(to_string(e.fault)) + (level ? " on" : " off");
        break;
      case TraceEventKind::load: {
        char buf[160];
        std::snprintf(buf, sizeof buf, "load: %.2f g·cm² inertia, %.6f N·m friction, %.6f N·m force",
                      e.load.inertia_g_mm2 / 100.0, e.load.friction_uNm / 1e6, e.load.force_uNm / 1e6);
        s.kind = "load";
        s.text = buf;
        break;
      }
      case TraceEventKind::axis:
        s.kind = "axis";
        s.text = e.text == "none" ? std::string("axis removed") : "axis attached: " + std::string(e.text);
        break;
      case TraceEventKind::stops:
        s.kind = "stops";
        s.text = "hard stops: " + (e.has_lower_stop ? std::to_string(e.lower_stop) : std::string()) + ".." +
                 (e.has_upper_stop ? std::to_string(e.upper_stop) : std::string()) + " (1/128 step)";
        break;
      case TraceEventKind::supply:
        s.kind = "supply";
        s.text = "motor supply " + std::to_string(e.supply_mV) + " mV";
        break;
      default: return;
    }
    ReportChip& c = chips_[e.chip];
    if (c.stimuli.size() < input_budget_) c.stimuli.push_back(std::move(s));
  }

  struct Seen {
    const Variant* table = nullptr;
    std::array<std::uint32_t, 32> value{};
    std::array<bool, 32> known{};
  };

  ReportChain& data_;
  Chain& chain_;
  const ReportOptions& options_;
  ChipNumbering numbering_;
  DivergenceWatch watch_;
  Keeper keeper_;
  bool counting_;
  bool thinned_ = false;  // a series was thinned on the way
  Collapser collapser_;
  std::vector<ReportChip> chips_;
  std::vector<Seen> seen_;
  std::vector<char> decoded_;  // this frame: 1 = a GetParam/GetStatus, 2 = a command that may change registers
  std::deque<PendingRow> pending_;
  std::uint64_t pending_base_ = 0;
  std::uint64_t frames_ = 0;
  std::vector<std::uint8_t> rx_;
  ProtocolTracker tracker_;
  Tick shown_to_, step_ = 1;
  std::size_t state_budget_ = 64, phase_budget_ = 64, register_budget_ = 64, input_budget_ = 64;
};

/// The sanitizer's rules on the frames: the bus calls of a board (ChainBus), one frame a use.
std::vector<Finding> sanitizer_pass(TraceReader& in, const TraceWorld& world, const ReportOptions& o,
                                    std::uint64_t& count) {
  Chain chain = world.make_chain();
  std::vector<Finding> out;
  CheckConfig config = world.board.check;
  config.level = CheckLevel::warn;  // a page shows every finding, whatever the run did with them
  Sanitizer sanitizer(config);
  sanitizer.set_broken_sink([&](const Violation& v) {
    ++count;
    if (out.size() >= o.limits.findings) return;
    const RuleInfo& info = rule_info(v.rule);
    Finding f;
    f.kind = "sanitizer";
    f.name = std::string(info.name);
    f.frame = v.frame;
    f.tick = v.tick;
    f.chip = v.chip;
    f.text = v.what;
    f.detail = std::string(info.about) + " (" + std::string(info.datasheet) + "; " + std::string(info.mark) + ")";
    out.push_back(std::move(f));
  });
  ProtocolTracker tracker(chain);  // pins, faults and loads as a replay applies them
  ChainChecker checker(sanitizer, chain, in.header().name, o.number_from);
  for (std::size_t k = 0; k < chain.size(); ++k)
    chain.chip(k).set_diagnostic_sink([&checker, k](const Diagnostic& d) { checker.chip_diagnostic(k, d); });
  const WireSettings wire{};  // a trace holds bytes as the chips took them: mode 3, MSB first, 8 bits
  std::vector<std::uint8_t> rx;
  TraceEvent e;
  while (in.next(e)) {
    if (e.kind != TraceEventKind::frame) {
      if (e.chip < chain.size()) tracker.apply(e);
      continue;
    }
    chain.advance_to(e.tick);
    checker.begin_use(wire);
    chain.select();
    checker.selected(e.tick, e.has_source_time());
    rx.resize(e.mosi.size());
    checker.clocked(e.mosi, wire, e.tick);
    chain.exchange(e.mosi, rx);
    chain.advance_to(e.end());
    checker.deselecting();
    chain.deselect();
    checker.deselected(e.end());
  }
  return out;
}

Finding divergence_finding(const Divergence& d) {
  Finding f;
  f.kind = "divergence";
  f.name = "replay";
  f.frame = d.frame;
  f.tick = d.tick;
  f.text = d.summary;
  f.detail = d.report;
  return f;
}

/// The chain a recording is of: its device node's name and its bus and chip select, from the
/// trace's board lines (whatever world it is run through); else the file's name.
std::pair<std::string, std::string> chain_name_of(const TraceFile& file) {
  const TraceHeader& h = file.header();
  if (!h.board.empty()) {
    const ChainDescription d = parse_chain_description(h.board, h.name);
    if (d.board) {
      const ChainConfig& c = d.chain();
      return {c.path.substr(c.path.rfind('/') + 1), "bus " + std::to_string(c.bus) + ", cs " + std::to_string(c.cs)};
    }
  }
  return {file.path().substr(file.path().rfind('/') + 1), ""};
}

}  // namespace

ReportChain make_report_chain(const TraceFile& file, const TraceWorld& world, const ReportOptions& options) {
  ReportChain data;
  std::tie(data.name, data.where) = chain_name_of(file);
  data.trace_path = file.path();
  data.trace_format = file.header().format;
  data.chain = world.summary() + " (" + world.how + ")";
  data.numbering = describe_numbering(options.number_from);
  data.notes = file.header().notes;
  if (world.overrides) data.notes.push_back(world.override_note(file.path()));
  std::uint64_t frames = 0;
  {
    auto in = file.read();
    TraceEvent e;
    while (in->next(e)) {
      data.end_tick = std::max(data.end_tick, e.kind == TraceEventKind::frame ? e.end() : e.tick);
      frames += e.kind == TraceEventKind::frame;
    }
  }
  Chain probe = world.make_chain();
  const std::size_t n = probe.size();

  MotionSeries motion;
  {
    auto in = file.read();
    Chain chain = world.make_chain();
    MotionOptions mo;
    mo.number_from = options.number_from;
    mo.max_points = std::clamp<std::size_t>(options.limits.motion_points / n, 64, kMaxMotionPoints);
    mo.max_commands = 0;
    motion = sample_motion(*in, chain, data.end_tick, mo);
    data.shown_to = motion.to;
  }
  // More frames than the timeline keeps: a first pass counts the rows each time slice would
  // show, so that the budget goes where the rows are.
  std::optional<std::vector<std::size_t>> shares;
  if (frames > options.limits.timeline_rows) {
    std::vector<std::size_t> counts(kSlices);
    auto in = file.read();
    Chain chain = world.make_chain();
    ReportChain scratch;
    FramePass pass(scratch, chain, options, in->header().name, data.end_tick, data.shown_to, nullptr, &counts);
    TraceEvent e;
    while (in->next(e)) {
      if (e.kind == TraceEventKind::frame)
        pass.frame(e);
      else
        pass.other(e, in->header().name);
    }
    pass.finish();
    shares = water_fill(counts, options.limits.timeline_rows - options.limits.timeline_rows / 5);
  }
  {
    auto in = file.read();
    Chain chain = world.make_chain();
    FramePass pass(data, chain, options, in->header().name, data.end_tick, data.shown_to, shares ? &*shares : nullptr);
    TraceEvent e;
    while (in->next(e)) {
      if (e.kind == TraceEventKind::frame)
        pass.frame(e);
      else
        pass.other(e, in->header().name);
    }
    pass.finish();
    data.diagnostics = pass.diagnostics_count;
    data.findings = std::move(pass.diagnostics);
  }
  for (ReportChip& c : data.chips)
    for (ChipMotion& m : motion.chips)
      if (m.chip == c.index) c.motion = std::move(m);
  {
    auto in = file.read();
    std::vector<Finding> found = sanitizer_pass(*in, world, options, data.sanitizer_findings);
    data.findings.insert(data.findings.end(), found.begin(), found.end());
  }
  if (!data.first_divergence.empty()) {
    auto in = file.read();
    Chain chain = world.make_chain();
    ReplayOptions ro;
    ro.keep_going = true;
    ro.max_reports = options.limits.findings;
    ro.number_from = options.number_from;
    const ReplayResult r = replay_trace(*in, chain, ro);
    for (const Divergence& d : r.divergences) data.findings.push_back(divergence_finding(d));
  }
  const std::uint64_t total = data.diagnostics + data.sanitizer_findings + data.divergent_frames + data.divergent_pins;
  data.findings_dropped = total > data.findings.size() ? total - data.findings.size() : 0;
  std::stable_sort(data.findings.begin(), data.findings.end(),
                   [](const Finding& a, const Finding& b) { return a.tick < b.tick; });
  return data;
}

std::vector<ReportLimits> share_limits(const ReportLimits& limits, const std::vector<std::uint64_t>& frames,
                                       const std::vector<std::size_t>& chips) {
  const std::size_t n = frames.size();
  if (n <= 1) return std::vector<ReportLimits>(n, limits);
  std::size_t all_chips = 0;
  for (std::size_t c : chips) all_chips += std::max<std::size_t>(1, c);
  std::vector<std::size_t> wanted;  // rows a chain could use: at most one per frame
  for (std::uint64_t f : frames)
    wanted.push_back(static_cast<std::size_t>(std::min<std::uint64_t>(f, limits.timeline_rows)));
  const std::vector<std::size_t> rows = water_fill(wanted, limits.timeline_rows);
  std::vector<ReportLimits> out(n, limits);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t mine = std::max<std::size_t>(1, k < chips.size() ? chips[k] : 1);
    auto per_chip = [&](std::size_t limit) { return std::max<std::size_t>(1, limit * mine / all_chips); };
    ReportLimits& l = out[k];
    // Frames beyond the chain's share are summarised: the share is exact where the chain has
    // fewer frames than it (all of them shown), a level the larger chains share otherwise.
    l.timeline_rows = std::max<std::size_t>(1, rows[k]);
    l.motion_points = per_chip(limits.motion_points);
    l.state_samples = per_chip(limits.state_samples);
    l.phase_samples = per_chip(limits.phase_samples);
    l.input_edges = per_chip(limits.input_edges);
    l.register_changes = per_chip(limits.register_changes);
    l.findings = std::max<std::size_t>(1, limits.findings / n);
  }
  return out;
}

std::uint64_t ReportData::frames() const {
  std::uint64_t n = 0;
  for (const ReportChain& c : chains) n += c.frames;
  return n;
}

std::size_t ReportData::chips() const {
  std::size_t n = 0;
  for (const ReportChain& c : chains) n += c.chips.size();
  return n;
}

std::uint64_t ReportData::findings() const {
  std::uint64_t n = 0;
  for (const ReportChain& c : chains) n += c.diagnostics + c.sanitizer_findings;
  return n;
}

bool ReportData::summarised() const {
  return std::any_of(chains.begin(), chains.end(), [](const ReportChain& c) { return c.summarised; });
}

ReportData make_report_data(const std::vector<ReportRecording>& recordings, const ReportOptions& options) {
  // A run records each chain once: two recordings of one chain are two runs, or a file twice.
  for (std::size_t a = 0; a < recordings.size(); ++a)
    for (std::size_t b = a + 1; b < recordings.size(); ++b) {
      const std::string& pa = recordings[a].file.path();
      const std::string& pb = recordings[b].file.path();
      std::error_code ec;
      if (pa == pb || std::filesystem::equivalent(pa, pb, ec))
        throw std::invalid_argument(quoted_text(pb) + " is given twice: give each chain's recording once");
      const auto na = chain_name_of(recordings[a].file), nb = chain_name_of(recordings[b].file);
      if (!na.second.empty() && na == nb)
        throw std::invalid_argument(quoted_text(pa) + " and " + quoted_text(pb) + " both record " + na.first + " (" +
                                    na.second + "): a page shows one run, with one recording per chain");
    }
  ReportData data;
  std::vector<ReportLimits> limits(recordings.size(), options.limits);
  if (recordings.size() > 1) {
    std::vector<std::uint64_t> frames;
    std::vector<std::size_t> chips;
    for (const ReportRecording& r : recordings) {
      auto in = r.file.read();
      std::uint64_t count = 0;
      TraceEvent e;
      while (in->next(e)) count += e.kind == TraceEventKind::frame;
      frames.push_back(count);
      chips.push_back(r.world.chain().chips.size());
    }
    limits = share_limits(options.limits, frames, chips);
  }
  for (std::size_t k = 0; k < recordings.size(); ++k) {
    ReportOptions o = options;
    o.limits = limits[k];
    data.chains.push_back(make_report_chain(recordings[k].file, recordings[k].world, o));
  }
  data.title = options.title;
  if (data.title.empty())
    for (std::size_t k = 0; k < recordings.size(); ++k) data.title += (k ? ", " : "") + recordings[k].file.path();
  return data;
}

// ---- JSON ------------------------------------------------------------------------------------

namespace {

using Json = nlohmann::ordered_json;

/// Strings shared by index: frames repeat the same bytes and texts over and over.
class StringTable {
 public:
  int id(const std::string& s) {
    if (s.empty()) return -1;
    auto [it, added] = ids_.try_emplace(s, static_cast<int>(list_.size()));
    if (added) list_.push_back(s);
    return it->second;
  }
  Json json() const { return list_; }

 private:
  std::map<std::string, int> ids_;
  std::vector<std::string> list_;
};

Json coverage_json(const CoverageData& data) {
  Json out = Json::array();
  for (const VariantCoverage& v : summarize(data)) {
    Json j;
    j["variant"] = v.variant;
    j["positions"] = v.positions;
    j["total"] = {v.total.hit, v.total.total};
    Json cats = Json::array();
    for (std::size_t c = 0; c < kCoverageCategoryCount; ++c) {
      Json cj;
      cj["name"] = std::string(to_string(static_cast<CoverageCategory>(c)));
      cj["hit"] = v.category[c].hit;
      cj["total"] = v.category[c].total;
      cj["against"] = counts_against(static_cast<CoverageCategory>(c));
      cj["missing"] = v.missing[c];
      cj["hit_points"] = v.hit[c];
      cats.push_back(std::move(cj));
    }
    j["categories"] = std::move(cats);
    j["raised_not_observed"] = v.raised_not_observed;
    out.push_back(std::move(j));
  }
  const CoverageCount total = coverage_total(data);
  return Json{{"variants", std::move(out)}, {"total", {total.hit, total.total}}};
}

Json campaign_page_json(const CampaignReport& r) {
  Json j;
  j["program"] = r.program;
  j["board"] = r.board;
  j["scenario"] = r.scenario;
  j["oracle"] = r.oracle;
  j["faults"] = r.faults;
  j["points"] = r.points;
  j["total"] = r.total;
  j["complete"] = r.complete;
  j["summary"] = campaign_summary(r);
  const FailOn fail_on;
  Json reruns = Json::array();
  for (const RerunResult& x : r.reruns) {
    Json y;
    y["index"] = x.index;
    y["fault"] = x.fault;
    y["chain"] = x.chain;
    y["chip"] = x.chip;
    y["point"] = x.point;
    y["tick"] = x.tick;
    y["after"] = x.after_command;
    y["verdict"] = std::string(to_string(x.verdict));
    y["flag_read"] = x.flag_read ? Json(*x.flag_read) : Json();
    y["traffic_differs"] = x.traffic_differs;
    y["exit"] = x.exit;
    y["program"] = x.program;
    y["fails"] = x.fails(fail_on);
    if (x.first_failure) {
      const ScenarioFailure& f = *x.first_failure;
      y["failure"] = f.where + ": " + f.chip + " " + f.what + " expected " + f.expected + ", seen " + f.seen;
    } else {
      y["failure"] = nullptr;
    }
    y["reproducer"] = x.reproducer;
    y["command"] = x.command;
    reruns.push_back(std::move(y));
  }
  j["reruns"] = std::move(reruns);
  return j;
}

}  // namespace

namespace {

Json chain_json(const ReportChain& d) {
  StringTable strings;
  Json j;
  j["name"] = d.name;
  j["where"] = d.where;
  j["trace"] = {{"path", d.trace_path}, {"format", d.trace_format}, {"chain", d.chain}, {"numbering", d.numbering},
                {"notes", d.notes}};
  j["frames"] = d.frames;
  j["end"] = d.end_tick;
  j["shown_to"] = d.shown_to;
  j["phase_step"] = d.phase_step;
  j["summarised"] = d.summarised;
  // Timeline: [tick, period, repetitions, first_frame, rows], each row [dt, duration, mosi, miso, flags, texts...].
  Json entries = Json::array();
  for (const ReportEntry& e : d.entries) {
    Json rows = Json::array();
    for (const ReportRow& r : e.rows) {
      Json row = {r.tick, r.duration, strings.id(r.mosi), strings.id(r.miso), (r.diverged ? 1 : 0) | (r.diagnostic ? 2 : 0)};
      for (const std::string& t : r.texts) row.push_back(strings.id(t));
      rows.push_back(std::move(row));
    }
    entries.push_back({e.tick, e.period, e.repetitions, e.first_frame, std::move(rows)});
  }
  j["entries"] = std::move(entries);
  Json gaps = Json::array();
  for (const ReportGap& g : d.gaps) gaps.push_back({g.from, g.to, g.first_frame, g.frames, g.commands});
  j["gaps"] = std::move(gaps);
  Json chips = Json::array();
  for (const ReportChip& c : d.chips) {
    Json cj;
    cj["index"] = c.index;
    cj["number"] = c.number;
    cj["variant"] = c.variant;
    Json fields = Json::array();
    for (const StatusField& f : c.status_fields) fields.push_back({f.name, f.bit, f.width, f.active_low});
    cj["status_fields"] = std::move(fields);
    Json live = Json::array();
    for (const auto& [address, name] : c.live_registers) live.push_back({address, name});
    cj["live_registers"] = std::move(live);
    // Columns, ticks as differences from the sample before (the file stays small).
    Json t = Json::array(), pos = Json::array(), el = Json::array(), speed = Json::array(), status = Json::array();
    Tick last = 0;
    for (const StateSample& s : c.states) {
      t.push_back(s.tick - last);
      last = s.tick;
      pos.push_back(s.abs_pos);
      el.push_back(s.el_pos);
      speed.push_back(s.speed);
      status.push_back(s.status);
    }
    cj["states"] = {{"dt", std::move(t)}, {"abs_pos", std::move(pos)}, {"el_pos", std::move(el)},
                    {"speed", std::move(speed)}, {"status", std::move(status)}};
    Json pt = Json::array(), pa = Json::array(), pb = Json::array();
    last = 0;
    for (const PhaseSample& s : c.phase) {
      pt.push_back(s.tick - last);
      last = s.tick;
      pa.push_back(s.coil_a);
      pb.push_back(s.coil_b);
    }
    cj["phase"] = {{"dt", std::move(pt)}, {"a", std::move(pa)}, {"b", std::move(pb)}};
    Json mt = Json::array(), mp = Json::array(), ms = Json::array(), mf = Json::array();
    last = 0;
    for (const MotionSample& s : c.motion.samples) {
      mt.push_back(s.tick - last);
      last = s.tick;
      mp.push_back(s.abs_pos);
      ms.push_back(s.speed);
      mf.push_back(s.mot_status | (s.busy ? 4 : 0) | (s.flag ? 8 : 0) | (s.sw ? 16 : 0) | (s.hiz ? 32 : 0));
    }
    cj["motion"] = {{"dt", std::move(mt)}, {"abs_pos", std::move(mp)}, {"speed", std::move(ms)}, {"bits", std::move(mf)},
                    {"microsteps", c.motion.microsteps_per_step}};
    Json regs = Json::array();
    for (const RegisterChange& r : c.registers) regs.push_back({r.tick, r.address, strings.id(r.name), r.value, strings.id(r.text)});
    cj["registers"] = std::move(regs);
    cj["register_changes_dropped"] = c.register_changes_dropped;
    Json inputs = Json::array();
    for (const TraceInputEdge& p : c.inputs) inputs.push_back({p.tick, p.pin, p.level ? 1 : 0});
    cj["inputs"] = std::move(inputs);
    cj["inputs_dropped"] = c.inputs_dropped;
    Json stimuli = Json::array();
    for (const Stimulus& s : c.stimuli) stimuli.push_back({s.tick, s.frame, s.kind, s.text});
    cj["stimuli"] = std::move(stimuli);
    chips.push_back(std::move(cj));
  }
  j["chips"] = std::move(chips);
  Json findings = Json::array();
  for (const Finding& f : d.findings) findings.push_back({f.kind, f.name, f.frame, f.tick, f.chip, f.text, f.detail});
  j["findings"] = std::move(findings);
  j["counts"] = {{"diagnostics", d.diagnostics},
                 {"sanitizer", d.sanitizer_findings},
                 {"divergent_frames", d.divergent_frames},
                 {"divergent_pins", d.divergent_pins},
                 {"findings_dropped", d.findings_dropped}};
  j["first_divergence"] = d.first_divergence;
  j["strings"] = strings.json();
  return j;
}

std::string dumped(const Json& j) { return j.dump(-1, ' ', false, Json::error_handler_t::replace); }

}  // namespace

std::string report_chain_json(const ReportChain& chain) { return dumped(chain_json(chain)); }

std::string report_json(const ReportData& d) {
  Json j;
  j["format"] = "l6470emu-report 2";
  j["title"] = d.title;
  j["tick_ns"] = 250;
  Tick shown_to = 0;
  for (const ReportChain& c : d.chains) shown_to = std::max(shown_to, c.shown_to);
  j["shown_to"] = shown_to;
  Json chains = Json::array();
  for (const ReportChain& c : d.chains) chains.push_back(chain_json(c));
  j["chains"] = std::move(chains);
  j["coverage"] = d.coverage ? coverage_json(*d.coverage) : Json();
  j["campaign"] = d.campaign ? campaign_page_json(*d.campaign) : Json();
  return dumped(j);
}

}  // namespace l6470emu
