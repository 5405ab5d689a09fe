// What the report page shows of a run, extracted with the existing views over its recordings:
// the frames and what each chip made of them (ProtocolTracker, as `decode`), the motion
// (sample_motion, as `plot`), the registers and phase drive as the emulated chips have them
// after each event, the sanitizer's findings (board/sanitizer.hpp) and the divergences
// (replay_trace). A run of several chains has a recording per chain (trace_path_for_chain):
// each is read on its own into a ReportChain, and the page's bounds are shared among them. Data
// only, in bounded amounts; tools/report_page.hpp writes the page. No model of its own.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "board/coverage.hpp"
#include "core/tick.hpp"
#include "daisychain/chip_numbering.hpp"
#include "daisychain/motion_series.hpp"
#include "tools/campaign_report.hpp"
#include "tools/trace_input.hpp"
#include "tools/trace_world.hpp"

namespace l6470emu {

/// How much of a run a page keeps, all its chains together. A run within these limits is shown
/// whole; a longer one is summarised: the timeline keeps its rows per time slice and stands the
/// rest as summarised spans (their frames counted exactly), and each series keeps, per time
/// slice, its first and last sample and those with the extremes.
struct ReportLimits {
  std::size_t timeline_rows = 100'000;   ///< frame rows kept in full, a repeated group counted once per row
  std::size_t motion_points = 60'000;   ///< position/speed samples, all chips together (sample_motion)
  std::size_t state_samples = 60'000;   ///< register samples after frames and events, all chips together
  std::size_t phase_samples = 120'000;  ///< phase drive samples, all chips together
  std::size_t input_edges = 20'000;     ///< SW/STCK/STBY input edges kept
  std::size_t findings = 1'000;         ///< diagnostics, sanitizer findings and divergences kept, each
  std::size_t register_changes = 20'000;  ///< register writes kept (the rest counted)
};

/// Choices for make_report_data.
struct ReportOptions {
  NumberFrom number_from = NumberFrom::miso;
  ReportLimits limits;
  /// While a chip moves its phase drive is looked at this often at least (fewer when the
  /// trace is long: the samples stay within limits.phase_samples).
  Tick phase_step = ticks_from_us(10);
  std::string title;  ///< the page's title ("" = the traces' names)
};

/// One frame as a row of the timeline: when, its bytes, what each chip made of it.
struct ReportRow {
  Tick tick = 0;      ///< CS falling edge (relative to its group's first row in a ReportEntry)
  Tick duration = 0;  ///< CS low, ticks
  std::string mosi;   ///< "D0 D0 D0"
  std::string miso;   ///< "7E 03 ??" ("" = not captured)
  /// Per chain index: the command the chip decoded at this frame's CS rising edge
  /// (describe_command), or for GetParam/GetStatus its answer (describe_answer), "" for none.
  std::vector<std::string> texts;
  bool diverged = false;    ///< a captured MISO byte the emulator gives differently
  bool diagnostic = false;  ///< a protocol diagnostic came with it
  bool operator==(const ReportRow&) const = default;
};

/// A run of the timeline: `rows` (ticks relative to the first) happening `repetitions` times,
/// each `period` after the one before. A single frame is one row, one repetition.
struct ReportEntry {
  Tick tick = 0;
  Tick period = 0;
  std::uint64_t repetitions = 1;
  std::uint64_t first_frame = 0;  ///< 0-based number of the first frame
  std::vector<ReportRow> rows;
  std::uint64_t frames() const { return repetitions * rows.size(); }
};

/// Frames summarised, not shown one by one (a trace beyond ReportLimits::timeline_rows).
struct ReportGap {
  Tick from = 0, to = 0;          ///< first frame's CS falling edge, last frame's rising edge
  std::uint64_t first_frame = 0;  ///< 0-based
  std::uint64_t frames = 0;
  std::uint64_t commands = 0;     ///< commands other than NOP, GetParam, GetStatus among them
};

/// A chip's registers and phase drive after a frame or an event (only when one changed).
struct StateSample {
  Tick tick = 0;
  std::int32_t abs_pos = 0;
  std::uint16_t el_pos = 0;
  std::int32_t speed = 0;  ///< SPEED, negative in reverse
  std::uint16_t status = 0;
  bool operator==(const StateSample&) const = default;
};

/// Coil A and B levels (daisychain/phase_drive.hpp), tenths of a percent of full scale.
struct PhaseSample {
  Tick tick = 0;
  std::int16_t coil_a = 0, coil_b = 0;
};

/// A register's new value (any register but the live ABS_POS, EL_POS, SPEED and STATUS).
struct RegisterChange {
  Tick tick = 0;
  std::uint8_t address = 0;
  std::string name;  ///< in the table in force ("KVAL_RUN", "TVAL_RUN" on a powerSTEP01 in current mode)
  std::uint32_t value = 0;
  std::string text;  ///< describe_value: "0x08A = 2008 step/s²"
};

/// A STATUS field of a chip's layout.
struct StatusField {
  std::string name;  ///< datasheet name: "HiZ", "BUSY", "MOT_STATUS", "TH_STATUS", "STEP_LOSS_A"...
  unsigned bit = 0;
  unsigned width = 1;
  bool active_low = false;
};

/// An input edge the trace drove (SW, STCK, STBY) or an observation it holds (BUSY, FLAG, SW of the axis).
struct TraceInputEdge {  // not board.hpp's PinEdge: one name, one definition in a program
  Tick tick = 0;
  std::string pin;  ///< "SW", "STCK", "STBY"
  bool level = true;
};

/// A stimulus from the physical world: a fault, a switch, the supply, a load, an axis.
struct Stimulus {
  Tick tick = 0;
  std::uint64_t frame = 0;  ///< 1-based frame number of the last frame before it (0 = none)
  std::string kind;         ///< "fault", "switch", "supply", "load", "axis", "stops", "standby"
  std::string text;
};

/// Everything about one chip.
struct ReportChip {
  std::size_t index = 0;   ///< chain index (0 drives MISO)
  std::size_t number = 0;  ///< as the page numbers it
  std::string variant;
  std::vector<StatusField> status_fields;
  /// ABS_POS, EL_POS, SPEED and STATUS in the variant's table: (address, name); their values are `states`.
  std::vector<std::pair<std::uint8_t, std::string>> live_registers;
  std::vector<StateSample> states;
  std::vector<PhaseSample> phase;
  std::vector<RegisterChange> registers;  ///< the power-up values at tick 0 first
  std::uint64_t register_changes_dropped = 0;
  std::vector<TraceInputEdge> inputs;
  std::uint64_t inputs_dropped = 0;
  std::vector<Stimulus> stimuli;
  ChipMotion motion;  ///< sample_motion's series
};

/// A finding tied to a frame: a protocol diagnostic, a broken sanitizer rule, a divergence.
struct Finding {
  std::string kind;         ///< "diagnostic", "sanitizer", "divergence"
  std::string name;         ///< WRONG_CMD, the rule's name, "MISO", ...
  std::uint64_t frame = 0;  ///< 1-based frame number (0 = before any frame)
  Tick tick = 0;
  std::string chip;         ///< "chip 1" as numbered, or ""
  std::string text;         ///< one line
  std::string detail;       ///< more lines (a divergence's full report, the datasheet's place)
};

/// One chain of the run, from its recording: its frames, chips and findings.
struct ReportChain {
  /// The chain's name as the board names it: its device node's ("spidev0.1", from the trace's
  /// board lines), or the trace's file name when the trace does not say.
  std::string name;
  std::string where;        ///< "bus 0, cs 1" ("" when the trace does not say)
  std::string trace_path, trace_format;
  std::string chain;        ///< "3*L6470 (from the trace's chain line)"
  std::string numbering;    ///< describe_numbering
  std::vector<std::string> notes;  ///< importer notes, the world's override note
  std::uint64_t frames = 0;
  Tick end_tick = 0;        ///< the trace's last event
  Tick shown_to = 0;        ///< the series' end (motion still going after the trace, up to 1 s)
  Tick phase_step = 0;      ///< the phase drive's sampling step while moving
  std::vector<ReportEntry> entries;
  std::vector<ReportGap> gaps;
  std::vector<ReportChip> chips;  ///< in the page's numbering order
  std::vector<Finding> findings;  ///< in frame order
  std::uint64_t diagnostics = 0, sanitizer_findings = 0, divergent_frames = 0, divergent_pins = 0;
  std::uint64_t findings_dropped = 0;
  std::string first_divergence;  ///< one line ("" = the emulator reproduces the trace)
  bool summarised = false;       ///< something was left out (ReportLimits)
};

/// The page's data: every chain of the run, and what belongs to the run as a whole.
struct ReportData {
  std::string title;
  std::vector<ReportChain> chains;  ///< in the order their recordings were given
  std::optional<CoverageData> coverage;
  std::optional<CampaignReport> campaign;

  std::uint64_t frames() const;    ///< all chains together
  std::size_t chips() const;       ///< all chains together
  std::uint64_t findings() const;  ///< diagnostics and sanitizer findings, all chains together
  bool summarised() const;         ///< some chain was summarised
};

/// A recording of one chain to read: the trace and the world it runs through.
struct ReportRecording {
  const TraceFile& file;
  const TraceWorld& world;
};

/// Each chain's share of the page's `limits` when the chains' recordings hold `frames` frames
/// and `chips` chips: the series and the per-chip lists in proportion to the chips, the
/// timeline's rows shared as the time slices share them (a chain with fewer frames than an
/// equal share keeps them all, the others share the rest equally), the findings equally. One
/// chain keeps `limits` as they are.
std::vector<ReportLimits> share_limits(const ReportLimits& limits, const std::vector<std::uint64_t>& frames,
                                       const std::vector<std::size_t>& chips);

/// Reads `file` through the chain of `world` and extracts what the page shows of it, within
/// `options.limits` (several passes over the trace). Throws TraceError for malformed input and
/// std::invalid_argument for a trace the chain cannot run (events naming chips outside it).
ReportChain make_report_chain(const TraceFile& file, const TraceWorld& world, const ReportOptions& options = {});

/// The page's data of a run from its chains' recordings (one or more), within
/// `options.limits` all together (share_limits; with several chains each recording is read once
/// more first, to count its frames). The title is `options.title`, else the traces' names.
/// Throws as make_report_chain.
ReportData make_report_data(const std::vector<ReportRecording>& recordings, const ReportOptions& options = {});

/// One chain as JSON (its own string table; deterministic: the same data, the same bytes).
std::string report_chain_json(const ReportChain& chain);

/// The page's data as JSON, the page's script reads it: the title, every chain
/// (report_chain_json), the coverage and the campaign. Deterministic.
std::string report_json(const ReportData& data);

}  // namespace l6470emu
