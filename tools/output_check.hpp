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

}  // namespace l6470emu
