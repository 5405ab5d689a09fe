// Whether a command's output file can be written, checked before the command does any work:
// a report that cannot be written is an error at start-up, not a silent loss at the end, and an
// output never overwrites one of the command's inputs.
#pragma once

#include <string>
#include <vector>

namespace l6470emu {

/// One line saying why `path` cannot be written as an output ("" when it can): an empty path, a
/// missing folder, something that is not a regular file (a device, a FIFO), a read-only file, or
/// the same file as one of `inputs` (device and inode, links followed). A file that did not exist
/// is not left behind by the check.
std::string output_problem(const std::string& path, const std::vector<std::string>& inputs);

/// Writes `text` as the whole of the file at `path` (truncated first); false when it could not.
bool write_whole_file(const std::string& path, const std::string& text);

/// `path` made absolute against the working directory and normalised ("a/../b" is "b"): for a
/// file named on the command line and handed to a program that may change directory.
std::string absolute_path(const std::string& path);

}  // namespace l6470emu
