// The preload's side of a campaign's snapshots (linux/fork_plan.hpp): at each rerun's injection
// tick, a program that is single-threaded there forks, and the child goes on as that rerun while
// the parent waits for a free slot and goes on as the clean run. docs/campaigns.md, § Snapshots.
#pragma once

#include <string>

#include "core/tick.hpp"
#include "linux/device_board.hpp"

namespace l6470emu::preload {

/// Reads the plan L6470EMU_FORK_PLAN names, if any (and takes the variable out of the
/// environment: the program's own children are no server). A plan that cannot be read ends
/// the program with status 2 and one line.
void start_fork_server(DeviceBoard& board);
/// The next injection tick still ahead (kNever: none, or no plan): virtual time stops there.
Tick fork_server_next_tick();
/// Virtual time reached `now`: the reruns injected at `now` are forked (or, when the program
/// cannot be, their directories say why). Called with the scheduler's lock held.
void fork_server_reached(Tick now);
/// A fork() of the program's own: the child is no server.
void fork_server_after_fork_child();
/// The program runs on a board of its own (a firmware program): no snapshot is taken here, and
/// no rerun's directory is written.
void fork_server_leave();
/// Whether the fork in progress is a snapshot's (the fork handlers leave the scheduler's lock,
/// which the snapshot holds, and the board's recordings alone).
bool snapshot_forking();

}  // namespace l6470emu::preload
