// Coverage reports: text, JSON and LCOV, all from summarize().
#include "board/coverage_report.hpp"

#include <algorithm>
#include <cstdio>
#include <set>
#include <nlohmann/json.hpp>

namespace l6470emu {

namespace {

std::string percent_text(const CoverageCount& c) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%5.1f%%", c.percent());
  return buf;
}

std::string row(std::string_view name, const CoverageCount& c) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "  %-20.*s %5llu / %-5llu %s\n", static_cast<int>(name.size()), name.data(),
                static_cast<unsigned long long>(c.hit), static_cast<unsigned long long>(c.total), percent_text(c).c_str());
  return buf;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

/// Chain positions in the order of their chains' lengths, then of their numbers.
std::vector<std::string> positions_in_order(const std::set<std::string>& positions) {
  std::vector<std::string> out(positions.begin(), positions.end());
  auto numbers = [](const std::string& p) {
    unsigned k = 0, n = 0;
    std::sscanf(p.c_str(), "chip %u of %u", &k, &n);
    return std::pair(n, k);
  };
  std::stable_sort(out.begin(), out.end(), [&](const std::string& a, const std::string& b) { return numbers(a) < numbers(b); });
  return out;
}

/// The points of a variant in listing order, with its chain positions (those present) before
/// the pin edges.
std::vector<CoveragePoint> listing_points(const CoverageUniverse& u, const CoverageData::PerVariant& v) {
  std::vector<CoveragePoint> points;
  bool positions_added = false;
  for (const CoveragePoint& p : u.points()) {
    if (p.category == CoverageCategory::pin_edges && !positions_added) {
      for (const std::string& pos : positions_in_order(v.positions))
        points.push_back({CoverageCategory::chain_positions, pos, "a command decoded by " + pos});
      positions_added = true;
    }
    points.push_back(p);
  }
  return points;
}

}  // namespace

std::vector<VariantCoverage> summarize(const CoverageData& data) {
  std::vector<VariantCoverage> out;
  for (const auto& [name, v] : data.variants()) {
    const CoverageUniverse* u = coverage_universe(name);
    if (!u) continue;
    VariantCoverage s;
    s.variant = name;
    s.positions = positions_in_order(v.positions);
    for (const CoveragePoint& p : listing_points(*u, v)) {
      const auto c = static_cast<std::size_t>(p.category);
      const bool hit = v.hit[c].count(p.name) != 0;
      ++s.category[c].total;
      if (hit) {
        ++s.category[c].hit;
        s.hit[c].push_back(p.name);
      } else {
        s.missing[c].push_back(p.name);
      }
    }
    const auto raised = static_cast<std::size_t>(CoverageCategory::flags_raised);
    const auto observed = static_cast<std::size_t>(CoverageCategory::flags_observed);
    for (const std::string& f : s.hit[raised])
      if (!v.hit[observed].count(f)) s.raised_not_observed.push_back(f);
    for (std::size_t c = 0; c < kCoverageCategoryCount; ++c)
      if (!counts_against(static_cast<CoverageCategory>(c))) {
        s.total.hit += s.category[c].hit;
        s.total.total += s.category[c].total;
      }
    out.push_back(std::move(s));
  }
  return out;
}

CoverageCount coverage_total(const CoverageData& data) {
  CoverageCount t;
  for (const VariantCoverage& v : summarize(data)) {
    t.hit += v.total.hit;
    t.total += v.total.total;
  }
  return t;
}

std::string coverage_text(const CoverageData& data, bool show_missing) {
  const auto variants = summarize(data);
  if (variants.empty()) return "interface coverage: no chip in use\n";
  std::string out;
  CoverageCount all;
  for (const VariantCoverage& v : variants) {
    out += v.variant + " (" + joined(v.positions) + ")\n";
    out += "  category               hit / total      %\n";
    for (std::size_t c = 0; c < kCoverageCategoryCount; ++c) {
      const auto cat = static_cast<CoverageCategory>(c);
      if (!counts_against(cat)) out += row(to_string(cat), v.category[c]);
    }
    out += row("total", v.total);
    all.hit += v.total.hit;
    all.total += v.total.total;
    const auto rules = static_cast<std::size_t>(CoverageCategory::rules_broken);
    out += "  rules broken: " + (v.hit[rules].empty() ? std::string("none") : joined(v.hit[rules])) + "\n";
    out += "  raised but never observed: " + (v.raised_not_observed.empty() ? std::string("none") : joined(v.raised_not_observed)) + "\n";
    if (show_missing) {
      out += "  never hit:\n";
      for (std::size_t c = 0; c < kCoverageCategoryCount; ++c) {
        const auto cat = static_cast<CoverageCategory>(c);
        if (counts_against(cat) || v.missing[c].empty()) continue;
        out += "    " + std::string(to_string(cat)) + ": " + joined(v.missing[c]) + "\n";
      }
    }
    out += "\n";
  }
  char buf[128];
  std::snprintf(buf, sizeof buf, "TOTAL %llu / %llu points hit (%.1f%%)\n", static_cast<unsigned long long>(all.hit),
                static_cast<unsigned long long>(all.total), all.percent());
  return out + buf;
}

std::string coverage_json_report(const CoverageData& data) {
  nlohmann::ordered_json j;
  j["format"] = "l6470emu-coverage-report";
  j["version"] = kCoverageFormatVersion;
  nlohmann::ordered_json vs = nlohmann::ordered_json::object();
  CoverageCount all;
  for (const VariantCoverage& v : summarize(data)) {
    nlohmann::ordered_json o;
    o["chain positions present"] = v.positions;
    nlohmann::ordered_json cats = nlohmann::ordered_json::object();
    for (std::size_t c = 0; c < kCoverageCategoryCount; ++c) {
      nlohmann::ordered_json k;
      k["hit"] = v.category[c].hit;
      k["total"] = v.category[c].total;
      k["hit points"] = v.hit[c];
      k["missing"] = v.missing[c];
      cats[std::string(to_string(static_cast<CoverageCategory>(c)))] = k;
    }
    o["categories"] = cats;
    o["raised but never observed"] = v.raised_not_observed;
    o["hit"] = v.total.hit;
    o["total"] = v.total.total;
    all.hit += v.total.hit;
    all.total += v.total.total;
    vs[v.variant] = o;
  }
  j["variants"] = vs;
  j["hit"] = all.hit;
  j["total"] = all.total;
  return j.dump(1) + "\n";
}

CoverageLcov coverage_lcov(const CoverageData& data, const std::string& listing_dir) {
  CoverageLcov out;
  out.tracefile = "TN:l6470emu_interface\n";
  for (const auto& [name, v] : data.variants()) {
    const CoverageUniverse* u = coverage_universe(name);
    if (!u) continue;
    const std::string path = listing_dir + "/" + name + ".interface";
    std::string listing = "# The " + name + "'s interface as l6470emu counts its coverage: a line per point.\n"
                          "# Generated by `l6470emu coverage report --format lcov`; see docs/coverage.md.\n";
    std::size_t line = 2;
    std::string records, functions, function_hits;
    std::uint64_t lines_found = 0, lines_hit = 0, fn_found = 0, fn_hit = 0;
    CoverageCategory current = CoverageCategory::count;
    std::uint64_t category_hits = 0;
    std::string category_name;
    auto close_category = [&] {
      if (current == CoverageCategory::count) return;
      function_hits += "FNDA:" + std::to_string(category_hits) + "," + category_name + "\n";
      ++fn_found;
      fn_hit += category_hits > 0;
    };
    for (const CoveragePoint& p : listing_points(*u, v)) {
      if (p.category != current) {
        close_category();
        current = p.category;
        category_hits = 0;
        category_name = std::string(to_string(current));
        for (char& ch : category_name)
          if (ch == ' ') ch = '_';
        listing += "\n";
        ++line;
        listing += "[" + std::string(to_string(current)) + "]" +
                   (counts_against(current) ? "  (a hit here is a rule broken: listed, never counted)" : "") + "\n";
        ++line;
        functions += "FN:" + std::to_string(line) + "," + category_name + "\n";
      }
      const bool hit = v.hit[static_cast<std::size_t>(p.category)].count(p.name) != 0;
      std::string text = p.name;
      if (text.size() < 40) text.resize(40, ' ');
      listing += text + "  " + p.about + (counts_against(p.category) && hit ? "  ** BROKEN **" : "") + "\n";
      ++line;
      if (counts_against(p.category)) continue;
      records += "DA:" + std::to_string(line) + "," + (hit ? "1" : "0") + "\n";
      ++lines_found;
      lines_hit += hit;
      category_hits += hit;
    }
    close_category();
    out.tracefile += "SF:" + path + "\n" + functions + function_hits + "FNF:" + std::to_string(fn_found) + "\nFNH:" +
                     std::to_string(fn_hit) + "\n" + records + "LF:" + std::to_string(lines_found) + "\nLH:" +
                     std::to_string(lines_hit) + "\nend_of_record\n";
    out.listings.emplace_back(path, listing);
  }
  return out;
}

}  // namespace l6470emu
