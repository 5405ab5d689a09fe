// A ctl command line as words: how `l6470emu ctl` writes its arguments into the one text line it
// sends and how the daemon reads them back, so that a word with a blank in it (a trace file named
// "run 1.bin") stays one word.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace l6470emu {

/// The line for `words`: joined by single blanks; a word that is empty or holds a blank, a tab,
/// a double quote or a backslash is written in double quotes, with \" and \\ inside them.
std::string join_control_words(const std::vector<std::string>& words);

/// The words of `line`: split at blanks and tabs, except inside double quotes, where \" is a quote
/// and \\ a backslash (the form join_control_words writes). An unclosed quote ends at the line's
/// end; a backslash outside quotes is an ordinary character.
std::vector<std::string> split_control_words(std::string_view line);

}  // namespace l6470emu
