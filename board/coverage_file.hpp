// The coverage file: CoverageData as JSON on disk, read whole, and merged into under a lock so
// that any number of processes ending at once (pytest -n workers, a forked program's children)
// all land in one file, none clobbering another. The board's one file besides its recordings.
#pragma once

#include <string>

#include "board/coverage.hpp"

namespace l6470emu {

/// The environment variable that asks a front (the preload, a firmware program) to collect
/// interface coverage and merge it into the file it names when the program ends.
inline constexpr const char* kCoverageEnv = "L6470EMU_COVERAGE";

/// Reads the coverage file at `path`; throws std::runtime_error with one line "PATH: why"
/// (missing, unreadable, empty, not a coverage file, another format version).
CoverageData read_coverage_file(const std::string& path);

/// Merges `data` into the coverage file at `path` (created when missing; an empty file counts as
/// no data): under an exclusive lock on the file, the union is written beside it and renamed
/// over it, so a reader never sees half a file and a kill loses nothing already there. Returns
/// "" or one line saying why not (the file left as it was).
std::string merge_into_coverage_file(const std::string& path, const CoverageData& data);

/// Whether `path` can take coverage at the end of a run, checked at its start: "" when its
/// directory is writable and the file, if there, is a coverage file of this version; else one
/// line saying why not.
std::string check_coverage_output(const std::string& path);

}  // namespace l6470emu
