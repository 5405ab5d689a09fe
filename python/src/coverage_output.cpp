// CoverageOutput: a Python object's coverage file, merged into on close, destruction and exit.
#include "coverage_output.hpp"

#include <cstdio>
#include <set>
#include <utility>

#include "board/coverage_file.hpp"

namespace l6470emu::python {
namespace {

/// Every live CoverageOutput (the GIL guards it).
std::set<CoverageOutput*>& live() {
  static auto* outputs = new std::set<CoverageOutput*>;  // never destroyed: destructors run at exit too
  return *outputs;
}

}  // namespace

CoverageOutput::CoverageOutput(std::string path, Source source) : path_(std::move(path)), source_(std::move(source)) {
  live().insert(this);
}

CoverageOutput::~CoverageOutput() {
  live().erase(this);
  if (const std::string why = flush(); !why.empty())
    std::fprintf(stderr, "l6470emu: coverage not written: %s\n", why.c_str());
}

std::string CoverageOutput::flush() {
  CoverageData data = source_();
  // Nothing new since the last merge: the file already holds it (merging is a union). A run that
  // met nothing still merges once, so that its variants and chain positions are in the file.
  if (ever_merged_ && data == merged_) return "";
  std::string why = merge_into_coverage_file(path_, data);
  if (why.empty()) {
    merged_ = std::move(data);
    ever_merged_ = true;
  }
  return why;
}

std::vector<std::string> CoverageOutput::flush_all() {
  std::vector<std::string> failed;
  for (CoverageOutput* out : live())
    if (std::string why = out->flush(); !why.empty()) failed.push_back(std::move(why));
  return failed;
}

}  // namespace l6470emu::python
