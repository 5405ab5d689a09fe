// The host's real clocks for the board's time (board/board_time.hpp): the kernel's
// CLOCK_MONOTONIC and CLOCK_REALTIME, and a sleep that wakes on time. Linux only.
#pragma once

#include <cstdint>

#include "board/board_time.hpp"

namespace l6470emu {

/// The kernel's clocks, read through the C library's own functions (never the preload library's
/// replacements, so virtual time cannot leak into the board's wall clock). sleep_until sleeps
/// until shortly before the deadline and spins the rest: a kernel spidev call returns when
/// its last bit is clocked, and a plain sleep overshoots by ~0.1 ms.
HostClock& real_host_clock();

/// CLOCK_MONOTONIC in nanoseconds, read as real_host_clock() does.
std::int64_t monotonic_ns();

}  // namespace l6470emu
