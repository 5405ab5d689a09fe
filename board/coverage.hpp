// Interface coverage: the behaviours of a chip variant a driver can meet (commands with their
// argument classes, registers read and written, refusals, STATUS flags raised and observed,
// faults and switch events, step modes, chain positions, pin edges waited on, sanitizer rules
// broken), derived from the variant's tables, and the set of them a run met. No I/O here: the
// collector is board/coverage_collector.hpp, the file board/coverage_file.hpp.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "core/status_layout.hpp"
#include "core/variant.hpp"

namespace l6470emu {

/// The kinds of coverage point, in the order reports list them.
enum class CoverageCategory : std::uint8_t {
  commands,           ///< each command, with its argument classes (FWD/REV, ACT=0/1, Move of 0 steps...)
  registers_read,     ///< GetParam of each register
  registers_written,  ///< SetParam of each writable register, accepted
  refusals,           ///< each refusal the chip makes (a WS write while moving, a GoTo while BUSY...)
  flags_raised,       ///< each STATUS flag set in the chip
  flags_observed,     ///< each STATUS flag the driver saw set (GetStatus, GetParam(STATUS), a pin read)
  events,             ///< each fault and switch event the chip met
  step_modes,         ///< each STEP_SEL a motion command ran in
  chain_positions,    ///< each chip of each chain in use that decoded a command
  pin_edges,          ///< each BUSY/FLAG edge the program waited on (an edge event, a read in a loop)
  rules_broken,       ///< each sanitizer rule broken: the goal is none (not counted in the totals)
  count
};
inline constexpr std::size_t kCoverageCategoryCount = static_cast<std::size_t>(CoverageCategory::count);

/// The name of a category in files and reports ("commands", "registers read", ...).
std::string_view to_string(CoverageCategory c);
/// The category called `name`, or CoverageCategory::count.
CoverageCategory coverage_category_named(std::string_view name);
/// Whether hits of the category are bad news (rules broken): left out of the totals.
constexpr bool counts_against(CoverageCategory c) { return c == CoverageCategory::rules_broken; }

/// One point: its category, its name within it, and a line saying what meets it.
struct CoveragePoint {
  CoverageCategory category = CoverageCategory::commands;
  std::string name;   ///< "Move of 0 steps", "ABS_POS", "STEP_LOSS_A", "1/16"...
  std::string about;  ///< "Move with N = 0: BUSY pulses, nothing moves"
};

/// Every point of one variant (chain positions aside: those come from the chains in use), in
/// report order, with look-ups by name.
class CoverageUniverse {
 public:
  explicit CoverageUniverse(const Variant& variant);

  const std::string& variant() const { return variant_; }
  const std::vector<CoveragePoint>& points() const { return points_; }
  /// Index of the point, or -1 when the variant has none such.
  int find(CoverageCategory c, std::string_view name) const;

 private:
  std::string variant_;
  std::vector<CoveragePoint> points_;
  std::unordered_map<std::string, int> index_;  // "category\tname" -> index
};

/// The universe of `variant` (built once; a powerSTEP01's holds the registers of both modes).
const CoverageUniverse& coverage_universe(const Variant& variant);
/// The universe of the variant called `name` (a Variant name), or nullptr.
const CoverageUniverse* coverage_universe(std::string_view name);

/// A STATUS flag as a coverage point: a bit (active high or low), or one value of a 2-bit field
/// (MOT_STATUS, TH_STATUS). `alarm`: the flag can pull FLAG low (a FLAG pin read low observes it).
struct StatusFlagPoint {
  std::string name;
  std::int8_t bit = 0;
  bool active_low = false;
  std::int8_t value = -1;  ///< -1: a single bit; else the field's value
  bool alarm = false;
  /// Whether `status` shows the flag set.
  bool set_in(std::uint16_t status) const {
    if (value >= 0) return ((status >> bit) & 3u) == static_cast<unsigned>(value);
    return (((status >> bit) & 1u) != 0) != active_low;
  }
};
/// The flags of a STATUS layout, in report order (as describe_status names them).
std::vector<StatusFlagPoint> status_flag_points(const StatusLayout& layout);

/// The name of STEP_SEL `step_sel` as a step-mode point ("full step", "1/2", ... "1/128").
std::string_view step_mode_name(std::uint8_t step_sel);

/// "chip K of N", the name of a chain position (K as the board numbers its chips).
std::string chain_position_name(std::size_t number, std::size_t chips);
/// Whether `name` is one chain_position_name writes (K < N, plain decimal numbers).
bool is_chain_position_name(std::string_view name);

/// What one or more runs met: per variant in use, the points hit and the chain positions
/// present. Merging is a union, so any order of merges gives the same data.
class CoverageData {
 public:
  struct PerVariant {
    std::array<std::set<std::string>, kCoverageCategoryCount> hit;
    std::set<std::string> positions;  ///< chain positions present (chain_position_name)
    bool operator==(const PerVariant&) const = default;
  };

  /// Marks a variant as in use (its report lists every point, hit or not).
  PerVariant& use(const std::string& variant) { return variants_[variant]; }
  /// Records a point as hit.
  void hit(const std::string& variant, CoverageCategory c, const std::string& name) {
    variants_[variant].hit[static_cast<std::size_t>(c)].insert(name);
  }
  /// Joins `other` into this.
  void merge(const CoverageData& other);
  const std::map<std::string, PerVariant>& variants() const { return variants_; }
  bool empty() const { return variants_.empty(); }
  bool operator==(const CoverageData&) const = default;

  /// The file's text: JSON with sorted keys, the same bytes for the same data.
  std::string to_json() const;
  /// Reads a file's text; throws std::runtime_error with one line (not a coverage file, another
  /// format version, a variant or a point this version does not know).
  static CoverageData from_json(std::string_view text);

 private:
  std::map<std::string, PerVariant> variants_;
};

/// The format version of coverage files this program reads and writes.
inline constexpr int kCoverageFormatVersion = 1;

}  // namespace l6470emu
