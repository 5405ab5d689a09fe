// PyChain: a chain, its host and an optional recorder (see py_chain.hpp).
#include "py_chain.hpp"

#include "board/board_config.hpp"
#include "board/trace_recorder.hpp"
#include "daisychain/chain_spec.hpp"
#include "spi/trace_native.hpp"

namespace l6470emu::python {

namespace {

/// The board description of a Python Chain: its chips (runs of one variant as NxNAME) and the
/// sanitizer's level and allowed rules.
std::string describe_python_chain(const std::vector<const Variant*>& variants, const CheckConfig& check) {
  BoardConfig config;
  config.chains.emplace_back().chips = variants;
  config.check = check;
  const std::string text = describe_board_config(config);
  // Only the chips and the checks: a spidev node, pins or a clock mean nothing to a Chain.
  const std::size_t chips = text.find("chips=");
  std::string out = text.substr(chips, text.find(' ', chips) - chips) + "\n";
  for (std::size_t at = text.find("\ncheck"); at != std::string::npos; at = text.find("\ncheck", at + 1))
    out += text.substr(at + 1, text.find('\n', at + 1) - at);
  return out;
}

}  // namespace

PyChain::PyChain(const std::vector<const Variant*>& variants, const RecordTo& record, Tick frame_gap,
                 const CheckConfig& check, const CoverageRequest& coverage)
    : chain_(std::make_unique<Chain>(make_chain(variants))),
      diagnostics_(std::make_unique<DiagnosticStore>()),
      frame_gap_(frame_gap) {
  check_lines_ = std::make_unique<std::vector<std::string>>();
  sanitizer_ = std::make_unique<Sanitizer>(
      check, [lines = check_lines_.get()](std::string_view line) {
        if (lines->size() < kMaxDiagnostics) lines->emplace_back(line);
      });
  checker_ = std::make_unique<ChainChecker>(*sanitizer_, *chain_, "Chain");
  if (coverage.collect) {
    coverage_ = std::make_unique<CoverageCollector>();
    coverage_->add_chain(*chain_);
    sanitizer_->set_broken_sink([cov = coverage_.get()](const Violation& v) {
      std::optional<std::size_t> chip;  // the chain index, or the whole chain
      if (!v.chip_key.empty() && v.chip_key.find_first_not_of("0123456789") == std::string::npos)
        chip = static_cast<std::size_t>(std::stoull(v.chip_key));
      cov->rule_broken(0, chip, v.rule);
    });
    for (std::size_t k = 0; k < chain_->size(); ++k)
      chain_->chip(k).set_command_sink([cov = coverage_.get(), chain = chain_.get(), k](const Opcode& op, std::uint32_t arg) {
        cov->command(0, k, chain->chip(k), op, arg);
      });
    coverage_->look(0, *chain_);  // the power-up flags (UVLO...) are raised
  }
  for (std::size_t k = 0; k < chain_->size(); ++k) {
    chain_->chip(k).set_diagnostic_sink([store = diagnostics_.get(), checker = checker_.get(), cov = coverage_.get(),
                                         k](const Diagnostic& d) {
      static constexpr const char* kKinds[] = {"wrong_cmd", "notperf_cmd", "ignored"};
      if (store->kept.size() == kMaxDiagnostics) {
        store->kept.pop_front();
        ++store->dropped;
      }
      store->kept.push_back({d.tick, k, kKinds[static_cast<int>(d.kind)], d.message});
      checker->chip_diagnostic(k, d);
      if (cov) cov->diagnostic(0, k, d);
    });
  }
  // The header's board lines: the variants and the checks (axes come as events when attached).
  const RecordOptions options{.board = describe_python_chain(variants, check)};
  if (!record.path.empty()) {
    file_ = std::make_unique<NativeTraceWriter>(record.path);  // throws std::runtime_error with the reason
    record_path_ = record.path;
    rec_ = std::make_unique<RecordingChain>(*chain_, *file_, options);
  } else if (record.memory) {
    memory_ = std::make_shared<Trace>();
    rec_ = std::make_unique<RecordingChain>(*chain_, *memory_, options);
  }
  bus_ = std::make_unique<ChainBus>(rec_ ? static_cast<SpiDevice&>(*rec_) : *chain_, *chain_, *checker_);
  bus_->set_untimed();  // time moves only when Python says so
  host_ = std::make_unique<ChainHost>(*chain_, *bus_, frame_gap_);
  // Last: a chain that failed to be built merges nothing.
  if (coverage_ && !coverage.path.empty())
    coverage_out_ = std::make_unique<CoverageOutput>(coverage.path, [cov = coverage_.get()] { return cov->data(); });
}

PyChain::~PyChain() {
  coverage_out_.reset();  // merged while the collector is there
  if (coverage_)
    for (std::size_t k = 0; k < chain_->size(); ++k) chain_->chip(k).set_command_sink({});
}

const std::string& PyChain::coverage_path() const {
  static const std::string none;
  return coverage_out_ ? coverage_out_->path() : none;
}

void PyChain::frame(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  bus_->begin({});
  bus_->select();
  bus_->exchange(tx, rx);
  bus_->deselect();
  bus_->end();
}

void PyChain::advance_to(Tick tick) {
  bus().advance_to(tick);
  if (rec_) rec_->observe_outputs();
  look();
}

void PyChain::set_sw_pin(std::size_t chip, bool level) {
  if (rec_)
    rec_->set_sw_pin(chip, level);
  else
    chain_->chip(chip).set_sw_pin(level);
  if (coverage_) coverage_->input(0, chip, Pin::SW, level);
  look();
}

void PyChain::set_stck_pin(std::size_t chip, bool level) {
  if (rec_)
    rec_->set_stck_pin(chip, level);
  else
    chain_->chip(chip).set_stck_pin(level);
  if (coverage_) coverage_->input(0, chip, Pin::STCK, level);
  look();
}

void PyChain::set_dir_pin(std::size_t chip, bool level) {
  if (rec_)
    rec_->set_dir_pin(chip, level);
  else
    chain_->chip(chip).set_dir_pin(level);
  if (coverage_) coverage_->input(0, chip, Pin::DIR, level);
  look();
}

void PyChain::set_stby_rst_pin(std::size_t chip, bool level) {
  if (rec_)
    rec_->set_stby_rst_pin(chip, level);
  else
    chain_->chip(chip).set_stby_rst_pin(level);
  if (coverage_) coverage_->input(0, chip, Pin::STBY_RST, level);
  look();
}

void PyChain::set_adc_input(std::size_t chip, std::uint8_t code) { fault(chip, TraceFault::ADCIN, code); }

void PyChain::fault(std::size_t chip, TraceFault fault, std::uint8_t value) {
  apply_fault_here(chip, fault, value);
  if (coverage_) coverage_->event(0, chip, fault, value);
  look();
}

void PyChain::apply_fault_here(std::size_t chip, TraceFault fault, std::uint8_t value) {
  if (!rec_) {
    apply_fault(*chain_, chip, fault, value);
    return;
  }
  switch (fault) {
    case TraceFault::UVLO: rec_->set_undervoltage(chip, value != 0); break;
    case TraceFault::UVLO_ADC: rec_->set_adc_undervoltage(chip, value != 0); break;
    case TraceFault::OCD: rec_->set_overcurrent(chip, value != 0); break;
    case TraceFault::STALL_A: rec_->set_stall(chip, Bridge::A, value != 0); break;
    case TraceFault::STALL_B: rec_->set_stall(chip, Bridge::B, value != 0); break;
    case TraceFault::THERMAL: rec_->set_thermal(chip, static_cast<Thermal>(value & 3)); break;
    case TraceFault::ADCIN: rec_->set_adc_input(chip, value); break;
    case TraceFault::POWER_CYCLE: rec_->power_cycle(chip); break;
    case TraceFault::MISO_FLIP: rec_->miso_flip(chip, value); break;
    case TraceFault::LOST_FRAME: rec_->lost_frame(chip); break;
  }
}

void PyChain::set_axis_load(std::size_t chip, const LoadSpec& load) {
  if (rec_)
    rec_->set_axis_load(chip, load);
  else
    chain_->chip(chip).set_axis_load(load);
  look();
}

void PyChain::attach_axis(std::size_t chip, const AxisSpec& spec) {
  if (rec_)
    rec_->attach_axis(chip, spec);
  else
    chain_->chip(chip).attach_axis(spec);
  look();
}

void PyChain::close() {
  if (!rec_) return;
  rec_->observe_outputs();
  bus_->set_device(*chain_);
  rec_.reset();
  file_.reset();
}

std::vector<ChainDiagnostic> PyChain::take_diagnostics(std::uint64_t& dropped) {
  std::vector<ChainDiagnostic> out(diagnostics_->kept.begin(), diagnostics_->kept.end());
  diagnostics_->kept.clear();
  dropped = diagnostics_->dropped;
  diagnostics_->dropped = 0;
  return out;
}

}  // namespace l6470emu::python
