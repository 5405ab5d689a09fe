// Coverage files: read whole, checked, and merged into through spi/file_update (a lock and a rename).
#include "board/coverage_file.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <filesystem>

#include "spi/file_update.hpp"

namespace l6470emu {

namespace {

CoverageData parse(const std::string& path, const std::string& text) {
  try {
    return CoverageData::from_json(text);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace

CoverageData read_coverage_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw std::runtime_error(path + ": a directory, not a coverage file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": " + (std::filesystem::exists(path, ec) ? "cannot be read" : "no such file"));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw std::runtime_error(path + ": cannot be read");
  if (text.str().empty()) throw std::runtime_error(path + ": empty, not a coverage file");
  return parse(path, text.str());
}

std::string merge_into_coverage_file(const std::string& path, const CoverageData& data) {
  return update_file_locked(path, [&](const std::string& old, std::string& error) -> std::string {
    CoverageData merged;
    try {
      if (!old.empty()) merged = parse(path, old);
    } catch (const std::exception& e) {
      error = std::string(e.what()) + " (left as it is)";
      return "";
    }
    merged.merge(data);
    return merged.to_json();
  });
}

std::string check_coverage_output(const std::string& path) {
  if (path.empty()) return "the coverage file name is empty";
  if (const std::string why = file_writable(path); !why.empty()) return why;
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) > 0 && !ec) {
    try {
      read_coverage_file(path);
    } catch (const std::exception& e) {
      return std::string(e.what()) + " (coverage is merged into it: name a new file, or remove this one)";
    }
  }
  return "";
}

}  // namespace l6470emu
