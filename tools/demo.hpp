// The `l6470emu demo` subcommand: a chain of emulated L6470s driven through
// spidev-style messages (struct spi_ioc_transfer semantics), printing what the chips did.
#pragma once

#include <cstddef>
#include <ostream>

namespace l6470emu {

/// Runs the demo with `chips` chips for `seconds` of virtual time; returns the exit status.
int run_demo(std::size_t chips, unsigned seconds, std::ostream& out);

}  // namespace l6470emu
