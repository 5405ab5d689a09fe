// `l6470emu plot`: the picture of what the motors did in a trace. The drawing is the Python
// module's (l6470emu.plot, matplotlib); this command finds Debian's python3 and the package
// (build tree or installed) and hands its arguments over. No plotting logic here.
#pragma once

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace l6470emu {

/// Where the l6470emu Python package is for the program at `exe` (its own path): the
/// directory to put on PYTHONPATH (`$L6470EMU_PYTHONPATH` when set; else the build tree's
/// python/ beside the program, or the dist-packages of the prefix it is installed in).
/// Empty when none holds the package (python3 may still find it on its own path).
std::string python_package_dir(const std::string& exe);

/// The command line that draws: python3 -m l6470emu.plot ARGS (`$L6470EMU_PYTHON`, default
/// /usr/bin/python3).
std::vector<std::string> plot_command(const std::vector<std::string>& args);

/// Adds `plot` to `app`. It runs in a CLI11 callback and replaces this process with python3;
/// when that cannot start it ends the program with status 2 and one line.
void add_plot_command(CLI::App& app);

}  // namespace l6470emu
