// Reports of interface coverage (docs/coverage.md): a table per variant and category with the
// points never hit, the same as JSON, and LCOV with a generated interface listing per variant,
// which genhtml and CI coverage viewers render. Text only: `l6470emu coverage` writes the files.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "board/coverage.hpp"

namespace l6470emu {

/// Hit and total points of one category, one variant, or everything (rules broken aside).
struct CoverageCount {
  std::uint64_t hit = 0, total = 0;
  /// hit / total in percent (100 when there is nothing to hit).
  double percent() const { return total == 0 ? 100.0 : 100.0 * static_cast<double>(hit) / static_cast<double>(total); }
  /// Whether the percentage is at least `pct`, exactly (no rounding).
  bool at_least(double pct) const { return static_cast<double>(hit) * 100.0 >= pct * static_cast<double>(total); }
};

/// One variant's numbers: each category's count and the points never hit, in listing order.
struct VariantCoverage {
  std::string variant;
  std::vector<std::string> positions;  ///< chain positions present
  CoverageCount category[kCoverageCategoryCount];
  std::vector<std::string> missing[kCoverageCategoryCount];
  std::vector<std::string> hit[kCoverageCategoryCount];
  std::vector<std::string> raised_not_observed;  ///< flags raised the driver never saw set
  CoverageCount total;                           ///< every category but rules broken
};

/// The numbers of every variant in `data`, by variant name.
std::vector<VariantCoverage> summarize(const CoverageData& data);
/// The total over every variant (rules broken aside).
CoverageCount coverage_total(const CoverageData& data);

/// The text report: a table per variant (hit / total, %), the flags raised but never observed,
/// the rules broken, and with `show_missing` every point never hit.
std::string coverage_text(const CoverageData& data, bool show_missing);
/// The same numbers as JSON (sorted, deterministic).
std::string coverage_json_report(const CoverageData& data);

/// An LCOV tracefile and the listings it points at: one file per variant in `listing_dir`
/// (an absolute directory), each point a line, hit once or not at all.
struct CoverageLcov {
  std::string tracefile;
  std::vector<std::pair<std::string, std::string>> listings;  ///< (path, text)
};
CoverageLcov coverage_lcov(const CoverageData& data, const std::string& listing_dir);

}  // namespace l6470emu
