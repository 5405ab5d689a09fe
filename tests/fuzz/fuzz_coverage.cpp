// libFuzzer harness of coverage files (board/coverage.hpp): whatever the bytes, CoverageData::
// from_json returns data or throws one std::runtime_error line; data it accepts writes back as
// JSON that reads back to the same data in the same bytes, merges with itself to itself, and goes
// through the three reports (text, JSON, LCOV) without a crash, each LCOV line record pointing
// at a line of its listing that names a point.
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "board/coverage.hpp"
#include "board/coverage_report.hpp"
#include "fuzz_support.hpp"

using namespace l6470emu;

namespace {

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

/// Every DA record of the tracefile names a line of its listing that begins with a point's name.
void check_lcov(const CoverageData& d, const CoverageLcov& lcov) {
  FUZZ_CHECK(lcov.listings.size() == d.variants().size(), "%zu listings for %zu variants", lcov.listings.size(),
             d.variants().size());
  std::vector<std::string> listing;
  std::string variant;
  for (const std::string& line : lines_of(lcov.tracefile)) {
    if (line.rfind("SF:", 0) == 0) {
      const std::string path = line.substr(3);
      listing.clear();
      for (const auto& [p, text] : lcov.listings)
        if (p == path) listing = lines_of(text);
      FUZZ_CHECK(!listing.empty(), "SF:%.200s has no listing", path.c_str());
      variant = path.substr(path.rfind('/') + 1);
      variant = variant.substr(0, variant.rfind('.'));
      continue;
    }
    if (line.rfind("DA:", 0) != 0) continue;
    const std::size_t comma = line.find(',');
    FUZZ_CHECK(comma != std::string::npos, "a DA line without a comma: %.200s", line.c_str());
    const unsigned long n = std::stoul(line.substr(3, comma - 3));
    FUZZ_CHECK(n >= 1 && n <= listing.size(), "DA line %lu outside a listing of %zu lines", n, listing.size());
    const std::string& text = listing[n - 1];
    const bool hit = line.substr(comma + 1) == "1";
    if (!hit) continue;
    const auto& v = d.variants().at(variant);
    bool named = false;
    for (const auto& names : v.hit)
      for (const std::string& name : names)
        if (text.rfind(name + "  ", 0) == 0) named = true;
    FUZZ_CHECK(named, "%s: DA:%lu,1 points at a line naming no hit point: %.200s", variant.c_str(), n, text.c_str());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  CoverageData d;
  try {
    d = CoverageData::from_json(text);
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    FUZZ_CHECK(!what.empty(), "an empty error");
    FUZZ_CHECK(what.find('\n') == std::string::npos, "the error is not one line: %.300s", what.c_str());
    FUZZ_CHECK(what.size() <= 300 + size, "an error of %zu characters for %zu bytes", what.size(), size);
    return 0;
  }
  // Accepted: it writes back, reads back the same, and the same bytes again.
  const std::string json = d.to_json();
  CoverageData back;
  try {
    back = CoverageData::from_json(json);
  } catch (const std::exception& e) {
    fuzz::violated("to_json's text does not read back: %.300s", e.what());
  }
  FUZZ_CHECK(back == d, "from_json(to_json(d)) differs from d");
  FUZZ_CHECK(back.to_json() == json, "to_json differs after a round trip");
  CoverageData twice = d;
  twice.merge(d);
  FUZZ_CHECK(twice == d, "merging data with itself changed it");
  CoverageData into_empty;
  into_empty.merge(d);
  FUZZ_CHECK(into_empty.to_json() == json, "merging into nothing changed the bytes");

  // The reports.
  const CoverageCount total = coverage_total(d);
  FUZZ_CHECK(total.hit <= total.total, "%llu of %llu points hit", static_cast<unsigned long long>(total.hit),
             static_cast<unsigned long long>(total.total));
  for (const VariantCoverage& v : summarize(d))
    for (std::size_t c = 0; c < kCoverageCategoryCount; ++c)
      FUZZ_CHECK(v.category[c].hit == v.hit[c].size() && v.category[c].total == v.hit[c].size() + v.missing[c].size(),
                 "%s: category %zu counts do not add up", v.variant.c_str(), c);
  const std::string report = coverage_text(d, true);
  FUZZ_CHECK(!report.empty() && report.back() == '\n', "the text report does not end with a newline");
  (void)coverage_text(d, false);
  const std::string json_report = coverage_json_report(d);
  FUZZ_CHECK(!json_report.empty(), "an empty JSON report");
  check_lcov(d, coverage_lcov(d, "/listings"));
  return 0;
}
