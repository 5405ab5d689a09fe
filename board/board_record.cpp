// Board: recording chains into native traces (start/stop, the routes SPI, pins and backdoor
// events take while a chain is recorded). The recording itself is ChainTraceRecorder's.
#include "board/board_chain.hpp"
#include "board/board_internal.hpp"

#include <algorithm>

namespace l6470emu {

SpiDevice& Board::spi_of(ChainState& c) {
  if (c.recorder) return c.recorder->device();
  return c.chain;
}

void Board::apply_input(ChainState& c, std::size_t chip, Pin pin, bool level) {
  c.touched = true;
  c.prediction_valid = false;
  if (coverage_) coverage_->input(c.index, chip, pin, level);
  if (c.recorder) {
    c.recorder->set_input(chip, pin, level);
    return;
  }
  Chip& ch = c.chain.chip(chip);
  if (pin == Pin::SW) ch.set_sw_pin(level);
  if (pin == Pin::STCK) ch.set_stck_pin(level);
  if (pin == Pin::DIR) ch.set_dir_pin(level);
  if (pin == Pin::STBY_RST) ch.set_stby_rst_pin(level);
}

void Board::drop_failed_recording(ChainState& c) {
  // The file failed (disk full, removed device): say so once and go on without it.
  log_(c.name + ": trace recording stopped: " + c.recorder->error());
  c.recorder.reset();
}

bool Board::inject_fault(std::size_t chain, std::size_t chip, TraceFault fault, std::uint8_t value) {
  if (chain >= chains_.size()) return false;
  ChainState& c = *chains_[chain];
  if (chip >= c.chain.size()) return false;
  catch_up(c);
  c.touched = true;
  c.prediction_valid = false;
  if (coverage_) coverage_->event(c.index, chip, fault, value);
  if (c.recorder)
    c.recorder->fault(chip, fault, value);
  else
    apply_fault(c.chain, chip, fault, value);
  emit_changes(c, c.chain.now());
  return true;
}

bool Board::set_axis_load(std::size_t chain, std::size_t chip, const LoadSpec& load) {
  if (chain >= chains_.size()) return false;
  ChainState& c = *chains_[chain];
  if (chip >= c.chain.size() || c.chain.chip(chip).axis() == nullptr) return false;
  catch_up(c);
  c.touched = true;
  c.prediction_valid = false;
  if (c.recorder)
    c.recorder->set_axis_load(chip, load);
  else
    c.chain.chip(chip).set_axis_load(load);
  // The description a later recording carries has the load as it is now.
  const std::size_t number = ChipNumbering(numbering_, c.chain.size()).number_of(chip);
  for (auto& [k, spec] : c.config.axes)
    if (k == number) spec.load = load;
  emit_changes(c, c.chain.now());
  return true;
}

/// Applies a change to chip `chip`'s axis through the recorder when there is one (`recorded`)
/// or to the chip (`direct`), and keeps the chain's description in step with `describe` (what
/// a recording started later says of the axis). False for a bad index, or for a chip without
/// an axis unless `needs_axis` is false.
bool Board::change_axis(std::size_t chain, std::size_t chip, bool needs_axis,
                        const std::function<void(RecordingChain&)>& recorded, const std::function<void(Chip&)>& direct,
                        const std::function<void(std::vector<std::pair<std::size_t, AxisSpec>>&, std::size_t)>& describe) {
  if (chain >= chains_.size()) return false;
  ChainState& c = *chains_[chain];
  if (chip >= c.chain.size() || (needs_axis && !c.chain.chip(chip).has_axis())) return false;
  catch_up(c);
  c.touched = true;
  c.prediction_valid = false;
  if (c.recorder)
    recorded(c.recorder->recording());
  else
    direct(c.chain.chip(chip));
  describe(c.config.axes, ChipNumbering(numbering_, c.chain.size()).number_of(chip));
  emit_changes(c, c.chain.now());
  return true;
}

namespace {

AxisSpec* described_axis(std::vector<std::pair<std::size_t, AxisSpec>>& axes, std::size_t number) {
  for (auto& [k, spec] : axes)
    if (k == number) return &spec;
  return nullptr;
}

}  // namespace

bool Board::attach_axis(std::size_t chain, std::size_t chip, const AxisSpec& spec) {
  return change_axis(
      chain, chip, false, [&](RecordingChain& r) { r.attach_axis(chip, spec); }, [&](Chip& ch) { ch.attach_axis(spec); },
      [&](auto& axes, std::size_t number) {
        if (AxisSpec* a = described_axis(axes, number)) {
          *a = spec;
          return;
        }
        axes.emplace_back(number, spec);
        std::sort(axes.begin(), axes.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
      });
}

bool Board::detach_axis(std::size_t chain, std::size_t chip) {
  return change_axis(
      chain, chip, true, [&](RecordingChain& r) { r.detach_axis(chip); }, [](Chip& ch) { ch.detach_axis(); },
      [](auto& axes, std::size_t number) {
        std::erase_if(axes, [number](const auto& a) { return a.first == number; });
      });
}

bool Board::set_axis_stops(std::size_t chain, std::size_t chip, bool has_lower, std::int64_t lower, bool has_upper,
                           std::int64_t upper) {
  return change_axis(
      chain, chip, true, [&](RecordingChain& r) { r.set_axis_stops(chip, has_lower, lower, has_upper, upper); },
      [&](Chip& ch) { ch.set_axis_stops(has_lower, lower, has_upper, upper); },
      [&](auto& axes, std::size_t number) {
        if (AxisSpec* a = described_axis(axes, number)) {
          a->has_lower_stop = has_lower;
          a->lower_stop = has_lower ? lower : 0;
          a->has_upper_stop = has_upper;
          a->upper_stop = has_upper ? upper : 0;
        }
      });
}

bool Board::set_axis_supply(std::size_t chain, std::size_t chip, std::uint32_t supply_mV) {
  return change_axis(
      chain, chip, true, [&](RecordingChain& r) { r.set_axis_supply(chip, supply_mV); },
      [&](Chip& ch) { ch.set_axis_supply(supply_mV); },
      [&](auto& axes, std::size_t number) {
        if (AxisSpec* a = described_axis(axes, number)) a->supply.supply_mV = supply_mV;
      });
}

std::string Board::start_recording(std::size_t chain, const std::string& path) {
  if (chain >= chains_.size()) return "no chain " + std::to_string(chain);
  ChainState& c = *chains_[chain];
  catch_up(c);
  c.recorder.reset();
  std::string error;
  c.recorder = ChainTraceRecorder::open(c.chain, path, describe_recorded_chain(config_, c.config), open_output_, error);
  if (!c.recorder) return error.empty() ? path + ": cannot record" : error;
  if (c.touched)
    log_(c.name + ": recording to " + path + " starts on chips that have already run: their state now is not in the "
         "trace, and a replay starts them at power-up");
  return "";
}

std::string Board::start_recording_all(const std::string& path) {
  for (std::size_t i = 0; i < chain_count(); ++i) {
    const std::string error = start_recording(i, trace_path_for_chain(path, chains_[i]->name, chain_count()));
    if (!error.empty()) return error;
  }
  return "";
}

bool Board::stop_recording(std::size_t chain, std::string* summary) {
  if (chain >= chains_.size() || !chains_[chain]->recorder) return false;
  ChainState& c = *chains_[chain];
  catch_up(c);
  record_outputs(c);  // the levels at the end
  if (!c.recorder) return true;  // the file had failed: already reported
  if (summary)
    *summary = std::to_string(c.recorder->frames()) + " frame" + (c.recorder->frames() == 1 ? "" : "s") + " to " +
               c.recorder->path();
  c.recorder.reset();
  return true;
}

std::string Board::recording_path(std::size_t chain) const {
  if (chain >= chains_.size() || !chains_[chain]->recorder) return "";
  return chains_[chain]->recorder->path();
}

void Board::abandon_recordings() {
  // Whoever holds the originals keeps writing them; these copies must add no lines, nor cut or
  // finish the file.
  for (auto& c : chains_) {
    if (c->recorder) c->recorder->abandon();
    c->recorder.reset();
  }
}

void Board::flush_recordings() {
  for (auto& c : chains_)
    if (c->recorder) {
      c->recorder->flush_if_due();
      if (!c->recorder->error().empty()) drop_failed_recording(*c);
    }
}

}  // namespace l6470emu
