// `l6470emu run`'s progress line, the program's side: the board's time and the SPI messages so
// far, kept in the page `run` names (kRunProgressEnv), which it reads while it waits.
#pragma once

#include <atomic>
#include <cstdint>

#include "core/tick.hpp"

namespace l6470emu::preload {

namespace detail {
extern std::atomic<std::uint64_t>* g_progress;  // the page's two words (tick, messages), or nullptr
}

/// Maps the file kRunProgressEnv names, if any (nothing is kept without it).
void start_progress();

/// Whether a progress page is mapped (the callers' time is read only then).
inline bool progress_kept() { return detail::g_progress != nullptr; }

/// The board's time is `tick` now.
inline void progress_time(Tick tick) {
  if (auto* w = detail::g_progress) w[0].store(tick, std::memory_order_relaxed);
}

/// One more SPI message was exchanged; the board's time is `tick`. Plain loads and stores, no
/// read-modify-write: two threads counting at once may lose one (a progress line, not a count).
inline void progress_message(Tick tick) {
  if (auto* w = detail::g_progress) {
    w[0].store(tick, std::memory_order_relaxed);
    w[1].store(w[1].load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }
}

}  // namespace l6470emu::preload
