// ChainTraceRecorder: a RecordingChain writing to a native trace file, with write errors caught.
#include "board/trace_recorder.hpp"

#include <exception>

#include "spi/recording_output.hpp"
#include "spi/trace_file.hpp"
#include "spi/trace_native.hpp"

namespace l6470emu {

/// The file, behind a sink that turns write errors into a stopped recording (no exception
/// may reach a host program's C call through the preload library).
class ChainTraceRecorder::Sink final : public TraceSink {
 public:
  explicit Sink(std::unique_ptr<TraceOutput> output) : writer_(std::move(output)) {}
  void write_header(const TraceHeader& h) override {
    guard([&] { writer_.write_header(h); });
  }
  void write(const TraceEvent& e) override {
    guard([&] { writer_.write(e); });
  }
  void flush_if_due() {
    guard([&] { writer_.flush_if_due(); });
  }
  void abandon() { writer_.abandon(); }
  std::string error;

 private:
  template <class F>
  void guard(F&& f) {
    if (!error.empty()) return;
    try {
      f();
    } catch (const std::exception& x) {
      error = x.what();
    } catch (...) {
      error = "trace write failed";
    }
  }
  NativeTraceWriter writer_;
};

std::unique_ptr<ChainTraceRecorder> ChainTraceRecorder::open(
    Chain& chain, const std::string& path, const std::string& board,
    const std::function<std::unique_ptr<TraceOutput>(const std::string&)>& open_output, std::string& error) noexcept {
  try {
    auto sink = std::make_unique<Sink>(open_output ? open_output(path) : open_recording_output(path));
    std::unique_ptr<ChainTraceRecorder> r(new ChainTraceRecorder(chain, std::move(sink), path, board));
    if (!r->error().empty()) {
      error = r->error();
      return nullptr;
    }
    return r;
  } catch (const std::exception& x) {
    error = x.what();
  } catch (...) {
    error = path + ": cannot record";
  }
  return nullptr;
}

ChainTraceRecorder::ChainTraceRecorder(Chain& chain, std::unique_ptr<Sink> sink, std::string path,
                                       const std::string& board)
    : sink_(std::move(sink)), error_(&sink_->error), recording_(chain, *sink_, RecordOptions{.board = board}),
      path_(std::move(path)) {}

ChainTraceRecorder::~ChainTraceRecorder() = default;

void ChainTraceRecorder::set_input(std::size_t chip, Pin pin, bool level) {
  if (pin == Pin::SW) recording_.set_sw_pin(chip, level);
  if (pin == Pin::STCK) recording_.set_stck_pin(chip, level);
  if (pin == Pin::DIR) recording_.set_dir_pin(chip, level);
  if (pin == Pin::STBY_RST) recording_.set_stby_rst_pin(chip, level);
}

void ChainTraceRecorder::fault(std::size_t chip, TraceFault fault, std::uint8_t value) {
  switch (fault) {
    case TraceFault::UVLO: recording_.set_undervoltage(chip, value != 0); break;
    case TraceFault::UVLO_ADC: recording_.set_adc_undervoltage(chip, value != 0); break;
    case TraceFault::OCD: recording_.set_overcurrent(chip, value != 0); break;
    case TraceFault::STALL_A: recording_.set_stall(chip, Bridge::A, value != 0); break;
    case TraceFault::STALL_B: recording_.set_stall(chip, Bridge::B, value != 0); break;
    case TraceFault::THERMAL: recording_.set_thermal(chip, static_cast<Thermal>(value & 3)); break;
    case TraceFault::ADCIN: recording_.set_adc_input(chip, value); break;
    case TraceFault::POWER_CYCLE: recording_.power_cycle(chip); break;
    case TraceFault::MISO_FLIP: recording_.miso_flip(chip, value); break;
    case TraceFault::LOST_FRAME: recording_.lost_frame(chip); break;
  }
}

void ChainTraceRecorder::set_axis_load(std::size_t chip, const LoadSpec& load) { recording_.set_axis_load(chip, load); }

void ChainTraceRecorder::mark_advance() { recording_.mark_advance(); }

void ChainTraceRecorder::flush_if_due() { sink_->flush_if_due(); }

void ChainTraceRecorder::abandon() { sink_->abandon(); }

void apply_fault(Chip& chip, TraceFault fault, std::uint8_t value) {
  switch (fault) {
    case TraceFault::UVLO: chip.set_undervoltage(value != 0); break;
    case TraceFault::UVLO_ADC: chip.set_adc_undervoltage(value != 0); break;
    case TraceFault::OCD: chip.set_overcurrent(value != 0); break;
    case TraceFault::STALL_A: chip.set_stall(Bridge::A, value != 0); break;
    case TraceFault::STALL_B: chip.set_stall(Bridge::B, value != 0); break;
    case TraceFault::THERMAL: chip.set_thermal(static_cast<Thermal>(value & 3)); break;
    case TraceFault::ADCIN: chip.set_adc_input(value); break;
    case TraceFault::POWER_CYCLE: chip.power_cycle(); break;
    case TraceFault::MISO_FLIP:
    case TraceFault::LOST_FRAME: break;  // the wire's: see the Chain overload
  }
}

void apply_fault(Chain& chain, std::size_t chip, TraceFault fault, std::uint8_t value) {
  switch (fault) {
    case TraceFault::POWER_CYCLE: chain.power_cycle(chip); break;
    case TraceFault::MISO_FLIP: chain.arm_miso_flip(chip, value & 7u); break;
    case TraceFault::LOST_FRAME: chain.arm_lost_frame(chip); break;
    default: apply_fault(chain.chip(chip), fault, value); break;
  }
}

std::string trace_path_for_chain(const std::string& path, const std::string& name, std::size_t chains) {
  if (chains <= 1) return path;
  // A ".gz" stays last: "run.trace.gz" -> "run.spidev0.1.trace.gz".
  const std::string gz = gzip_file_name(path) ? ".gz" : "";
  const std::string base = path.substr(0, path.size() - gz.size());
  const std::size_t slash = base.rfind('/');
  const std::size_t dot = base.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash) || dot == (slash == std::string::npos ? 0 : slash + 1))
    return base + "." + name + gz;
  return base.substr(0, dot) + "." + name + base.substr(dot) + gz;
}

}  // namespace l6470emu
