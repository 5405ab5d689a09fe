// Board: recording chains into native traces (start/stop, the routes SPI, pins and backdoor
// events take while a chain is recorded). The recording itself is ChainTraceRecorder's.
#include "board/board_chain.hpp"
#include "board/board_internal.hpp"

namespace l6470emu {

SpiDevice& Board::spi_of(ChainState& c) {
  if (c.recorder) return c.recorder->device();
  return c.chain;
}

void Board::apply_input(ChainState& c, std::size_t chip, Pin pin, bool level) {
  c.touched = true;
  c.prediction_valid = false;
  if (c.recorder) {
    c.recorder->set_input(chip, pin, level);
    return;
  }
  Chip& ch = c.chain.chip(chip);
  if (pin == Pin::SW) ch.set_sw_pin(level);
  if (pin == Pin::STCK) ch.set_stck_pin(level);
  if (pin == Pin::STBY_RST) ch.set_stby_rst_pin(level);
}

void Board::record_outputs(ChainState& c) {
  if (!c.recorder) return;
  c.recorder->observe_outputs();  // free when nothing changed since the last look
  if (!c.recorder->error().empty()) {
    // The file failed (disk full, removed device): say so once and go on without it.
    log_(c.name + ": trace recording stopped: " + c.recorder->error());
    c.recorder.reset();
  }
}

bool Board::inject_fault(std::size_t chain, std::size_t chip, TraceFault fault, std::uint8_t value) {
  if (chain >= chains_.size()) return false;
  ChainState& c = *chains_[chain];
  if (chip >= c.chain.size()) return false;
  catch_up(c);
  c.touched = true;
  c.prediction_valid = false;
  if (c.recorder)
    c.recorder->fault(chip, fault, value);
  else
    apply_fault(c.chain.chip(chip), fault, value);
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
      if (!c->recorder->error().empty()) {
        log_(c->name + ": trace recording stopped: " + c->recorder->error());
        c->recorder.reset();
      }
    }
}

}  // namespace l6470emu
