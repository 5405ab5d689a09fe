// Bisection over ticks: the first tick of a range at which a monotone condition holds.
// Used by the event-driven engine (ramp ends) and the mechanical axis (switch and stop points).
#pragma once

#include "core/tick.hpp"

namespace l6470emu {

/// The smallest i in [lo, hi] with pred(i) true, where pred is monotone (false ... true);
/// hi + 1 when pred(hi) is false or the range is empty.
template <class Pred>
Tick first_true(Tick lo, Tick hi, Pred pred) {
  if (lo > hi || !pred(hi)) return hi + 1;
  while (lo < hi) {
    const Tick mid = lo + (hi - lo) / 2;
    if (pred(mid))
      hi = mid;
    else
      lo = mid + 1;
  }
  return lo;
}

}  // namespace l6470emu
