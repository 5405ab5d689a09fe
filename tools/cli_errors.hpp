// Usage errors of the l6470emu program, in one place: every mistake on the command line is one
// line naming the subcommand, with a suggestion for a near miss, and exit status 2.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
class Validator;
}  // namespace CLI

namespace l6470emu {

/// Exit status of every usage error (an unknown subcommand or option, a bad or missing value).
inline constexpr int kUsageError = 2;

/// A CLI11 check that the value is one of `names`; its message lists them and names the near
/// miss: "'nativ' is not one of auto, native, saleae; did you mean 'native'?".
CLI::Validator one_of(std::vector<std::string> names);

/// "; did you mean 'replay'?" (or "'a' or 'b'") when `word` is a near miss of a candidate, else "".
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);

/// Parses the command line with `app` (subcommand callbacks run inside). Returns the status to
/// exit with when the program should end here: after --help or --version (0, printed on
/// `out`), a callback's own status (CLI::RuntimeError), or a usage error: one line
/// "l6470emu SUB: ..." on `err` and kUsageError. Returns nullopt when the program goes on.
std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv, std::ostream& out, std::ostream& err);

}  // namespace l6470emu
