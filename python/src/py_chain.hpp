// The state behind l6470emu.Chain: a daisy chain, the reference host driving it, and, when
// asked, a RecordingChain in front of it so that every frame, pin and fault goes into a
// native trace (a file flushed event by event, or a Trace in memory). Frames go through the
// board's ChainBus, watched by the driver sanitizer (check=). Diagnostics the chips raise are
// kept for Python to take. Interface coverage (coverage=) is collected as the board collects it
// and merged into its file on close(), destruction or exit. No Python types here;
// chain_bindings.cpp wraps it.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "board/chain_bus.hpp"
#include "board/coverage_collector.hpp"
#include "board/sanitizer.hpp"
#include "daisychain/chain.hpp"
#include "daisychain/host.hpp"
#include "daisychain/recording_chain.hpp"
#include "spi/trace.hpp"
#include "coverage_output.hpp"

namespace l6470emu::python {

/// A diagnostic of one chip of the chain (WRONG_CMD, NOTPERF_CMD, ignored input).
struct ChainDiagnostic {
  Tick tick = 0;
  std::size_t chip = 0;
  std::string kind;  ///< "wrong_cmd", "notperf_cmd", "ignored"
  std::string message;
};

/// How a Chain records, if at all.
struct RecordTo {
  bool memory = false;  ///< into a Trace in memory
  std::string path;     ///< into a native trace file (when not empty)
};

/// A chain as the Python module sees it. Not thread-safe: the GIL serialises callers.
class PyChain {
 public:
  /// Diagnostics kept at most (older ones are dropped and counted).
  static constexpr std::size_t kMaxDiagnostics = 10000;

  PyChain(const std::vector<const Variant*>& variants, const RecordTo& record, Tick frame_gap,
          const CheckConfig& check = {CheckLevel::error, {}}, const CoverageRequest& coverage = {});
  ~PyChain();
  PyChain(const PyChain&) = delete;
  PyChain& operator=(const PyChain&) = delete;

  Chain& chain() { return *chain_; }
  const Chain& chain() const { return *chain_; }
  /// What frames go through: the sanitizer's bus in front of the recorder when recording, else
  /// in front of the chain.
  SpiDevice& bus() { return *bus_; }
  ChainHost& host() { return *host_; }

  /// One CS frame through the bus.
  void frame(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx);
  /// Lets time run to `tick` (recording BUSY/FLAG changes seen at the end).
  void advance_to(Tick tick);

  // The physical world, recorded when recording.
  void set_sw_pin(std::size_t chip, bool level);
  void set_stck_pin(std::size_t chip, bool level);
  void set_dir_pin(std::size_t chip, bool level);
  void set_stby_rst_pin(std::size_t chip, bool level);
  void set_adc_input(std::size_t chip, std::uint8_t code);
  /// A backdoor event as in a trace: UVLO/UVLO_ADC/OCD/STALL_A/STALL_B 0 or 1, THERMAL 0..3, ADCIN 0..31.
  void fault(std::size_t chip, TraceFault fault, std::uint8_t value);
  /// The load on `chip`'s axis changes (a load event when recording).
  void set_axis_load(std::size_t chip, const LoadSpec& load);
  /// Attaches an axis to `chip` (an axis event when recording).
  void attach_axis(std::size_t chip, const AxisSpec& spec);

  bool recording() const { return rec_ != nullptr; }
  /// The file being (or last) recorded into; empty for none or memory.
  const std::string& record_path() const { return record_path_; }
  /// The trace recorded in memory (also after close()), or nullptr.
  const Trace* memory_trace() const { return memory_.get(); }
  /// Stops recording (the file is closed); the chain stays usable.
  void close();

  /// Takes the diagnostics kept so far; `dropped` gets how many were not kept.
  std::vector<ChainDiagnostic> take_diagnostics(std::uint64_t& dropped);

  /// The sanitizer's settings (check=, check_allow=).
  const CheckConfig& check() const { return sanitizer_->config(); }
  void set_check(const CheckConfig& c) { sanitizer_->set_config(c); }
  /// Lines check=warn logged since the last call.
  std::vector<std::string> take_check_lines() {
    std::vector<std::string> out;
    out.swap(*check_lines_);
    return out;
  }
  /// Under check=error: the report of the first broken rule, taken.
  /// The failure's report, worded for an exception (SanitizerError).
  std::optional<std::string> take_check_failure() { return sanitizer_->take_failure(FailureEnd::raised); }

  // ---- interface coverage (coverage=) ---------------------------------------------

  bool collecting_coverage() const { return coverage_ != nullptr; }
  /// The coverage file merged into ("" for none or in memory only).
  const std::string& coverage_path() const;
  /// What the chain has met so far (empty data when coverage is off).
  CoverageData coverage() const { return coverage_ ? coverage_->data() : CoverageData{}; }
  /// Merges what is new into the coverage file: "" or one line why not.
  std::string flush_coverage() { return coverage_out_ ? coverage_out_->flush() : std::string(); }
  /// After a step of the run (SPI traffic through the host or frame()): the flags every chip shows.
  void look() {
    if (coverage_) coverage_->look(0, *chain_);
  }
  /// The host read output `pin` (BUSY, FLAG) of `chip` (busy_pin(), flag_pin()).
  void note_output_read(std::size_t chip, Pin pin, bool level) {
    if (coverage_) coverage_->output_read(0, chip, chain_->chip(chip), pin, level);
  }

 private:
  void apply_fault_here(std::size_t chip, TraceFault fault, std::uint8_t value);  // through the recorder if any

  struct DiagnosticStore {
    std::deque<ChainDiagnostic> kept;
    std::uint64_t dropped = 0;
  };

  // Destroyed bottom-up: the host and the recorder refer to what is above them.
  std::unique_ptr<Chain> chain_;
  std::unique_ptr<DiagnosticStore> diagnostics_;
  std::shared_ptr<Trace> memory_;
  std::unique_ptr<TraceSink> file_;
  std::unique_ptr<RecordingChain> rec_;
  std::unique_ptr<std::vector<std::string>> check_lines_;
  std::unique_ptr<Sanitizer> sanitizer_;
  std::unique_ptr<ChainChecker> checker_;
  std::unique_ptr<ChainBus> bus_;
  std::unique_ptr<ChainHost> host_;
  std::string record_path_;
  Tick frame_gap_;
  // Coverage: the chips' command sinks, their diagnostic sink and the sanitizer feed the
  // collector; the output (destroyed first, in ~PyChain) merges it into the file.
  std::unique_ptr<CoverageCollector> coverage_;
  std::unique_ptr<CoverageOutput> coverage_out_;
};

}  // namespace l6470emu::python
