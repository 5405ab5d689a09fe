// Where the program's companions are at run time: the preload library beside the program in a
// build tree, or where `cmake --install` / the .deb put it relative to the installed program.
#pragma once

#include <string>

namespace l6470emu {

/// This program's own path (/proc/self/exe), or "" when it cannot be read.
std::string own_program_path();

/// The preload library for the program at `exe`: $L6470EMU_PRELOAD when set; else
/// libl6470emu-preload.so beside `exe` (a build tree); else the installed one, found from the
/// program's directory by the install layout (bin/ -> lib/l6470emu/); else "" when none exists.
std::string preload_library_path(const std::string& exe);

}  // namespace l6470emu
