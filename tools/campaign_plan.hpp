// A fault campaign's plan (docs/campaigns.md): the faults a chip can be given, what its clean run
// did (every command each chip decoded, its BUSY pulses, its state at the end), the injection
// points derived from that, and each rerun's scenario. Reads traces and writes scenarios; runs
// no program (cmd_campaign does) and judges nothing (campaign_report does).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "board/board_config.hpp"
#include "board/scenario.hpp"
#include "core/commands.hpp"
#include "core/variant.hpp"

namespace l6470emu {

/// The faults a campaign raises, by the names `--faults` takes.
enum class CampaignFault : std::uint8_t {
  ocd, thermal_warning, thermal_bridge_shutdown, thermal_device_shutdown, uvlo, uvlo_adc, stall_a, stall_b,
  sw_close, reset, stby_pulse, miso_flip, lost_frame, block,
};

/// What a campaign knows of a fault.
struct FaultSpec {
  CampaignFault fault;
  std::string_view name;  ///< as --faults takes it ("thermal_warning")
  /// The STATUS flag a driver reads to see it ("OCD"; "" when no flag tells: a wire fault). A
  /// stall names bridge A's or B's flag by the variant (stall_flag_name).
  std::string_view flag;
  std::string_view what;  ///< one line: what the chip (or the wire) does
};

/// Every fault, in the order campaigns run them.
std::span<const FaultSpec> campaign_faults();
/// The fault called `name`, or nullptr.
const FaultSpec* find_campaign_fault(std::string_view name);
/// Why chip `variant` (with an axis or not) cannot be given `fault` ("" when it can).
std::string fault_unavailable(CampaignFault fault, const Variant& variant, bool has_axis);
/// The STATUS flag a driver reads to see `fault` on `variant` ("" when none).
std::string fault_flag(CampaignFault fault, const Variant& variant);
/// How long a fault condition lasts before the world clears it (a dip, a transient overcurrent):
/// the campaign's faults are events, not states the board is left in.
inline constexpr Tick kFaultHoldTicks = kTicksPerSecond / 100;

/// One command a chip decoded.
struct DecodedCommand {
  Command command = Command::NOP;
  std::uint8_t param = 0;  ///< SetParam/GetParam: the register's address
  Tick start = 0;          ///< CS fall of the frame that completed it
  Tick end = 0;            ///< CS rise of that frame: when the chip decoded it
};

/// One chip as the clean run left it.
struct ChipRun {
  std::size_t chain = 0;   ///< board chain index
  std::size_t index = 0;   ///< chain index of the chip (0 drives MISO)
  std::size_t number = 0;  ///< the chip's number as users give it (numbering=)
  std::string chain_name;  ///< "spidev0.0"
  const Variant* variant = nullptr;
  bool has_axis = false;
  std::vector<DecodedCommand> commands;  ///< NOPs left out
  std::vector<std::pair<Tick, Tick>> busy_low;  ///< BUSY low from .first to .second (kNever: to the end)
  /// At the end of the run: ABS_POS, MARK and every register the driver wrote (name, value as
  /// a scenario's register expectation reads it), STATUS's HiZ, BUSY and DIR.
  std::vector<std::pair<std::string, std::int64_t>> final_registers;
  std::vector<std::pair<std::string, bool>> final_status;
  /// True position of the rotor at each injection point (block's hard stop), by tick.
  std::vector<std::pair<Tick, std::int64_t>> rotor_at;
};

/// Reads the clean run's recording of board chain `chain` (a native trace) into its chips, up
/// to `end_tick` (the program's end). Throws TraceError for an unreadable trace.
std::vector<ChipRun> read_clean_run(const std::string& trace_path, std::size_t chain, const BoardConfig& board,
                                    Tick end_tick);

/// Where a fault goes in: a tick of the clean run and what it follows.
struct InjectionPoint {
  std::string name;           ///< "after_config", "at_Move", "during_motion_2", "idle_polling", "before_last_command"
  Tick tick = 0;
  std::string after_command;  ///< the datasheet name of the last command the chip decoded before it ("" none)
};

/// How points are chosen: `phases` (default), `every-command`.
enum class PointSelection : std::uint8_t { phases, every_command };

/// The injection points of one chip, in time order, each before its last command (so that the
/// driver could still see every fault); empty when the chip was sent fewer than one command.
std::vector<InjectionPoint> injection_points(const ChipRun& chip, PointSelection selection);

/// The rotor positions to sample for `block` at `ticks` (read_clean_run's second pass fills
/// ChipRun::rotor_at): the ticks of every point of every chip with an axis.
void sample_rotor_positions(const std::string& trace_path, std::size_t chain, const BoardConfig& board,
                            std::vector<ChipRun>& chips, const std::vector<std::vector<Tick>>& ticks_per_chip);

/// The steps that raise `fault` on `chip` at `tick` (and end it kFaultHoldTicks later where it
/// is a condition); `rotor` is the rotor's true position then (block only).
std::vector<ScenarioStep> fault_steps(CampaignFault fault, const ChipRun& chip, Tick tick, std::int64_t rotor);

/// The oracle when the user gave none: at the end, every chip's final_registers and
/// final_status as the clean run left them.
std::vector<ScenarioStep> clean_run_oracle(const std::vector<ChipRun>& chips);

/// The words of a comma-separated option value ("ocd,uvlo" -> ocd, uvlo; "" -> one empty word).
std::vector<std::string> comma_list(std::string_view list);

/// Whether `scenario` has an expectation of its own (then it is the oracle).
bool has_expectations(const Scenario& scenario);

}  // namespace l6470emu
