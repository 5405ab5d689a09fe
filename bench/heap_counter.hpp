// Heap accounting for the memory figures: heap_counter.cpp replaces the global operator
// new/delete of a program it is linked into and counts the bytes requested.
#pragma once

#include <cstddef>

namespace l6470emu::bench {

/// Bytes requested through operator new and not yet deleted.
std::size_t live_heap_bytes();
/// High-water mark of live_heap_bytes() since the last reset_peak_heap_bytes().
std::size_t peak_heap_bytes();
/// Starts a new high-water mark at the current live bytes.
void reset_peak_heap_bytes();

}  // namespace l6470emu::bench
