// What the Arduino front's files share: the runtime as the Arduino front opens it, and the
// runtime interrupt behind an attachInterrupt number. Not installed.
#pragma once

#include "firmware/runtime.hpp"

namespace l6470emu::arduino {

/// The program's runtime, opened for the Arduino front.
FirmwareRuntime& runtime();
/// Whatever the program's standard input holds for Serial, into the runtime's Serial input
/// (stdin_input.cpp: all of it, up to EOF and 1 MiB, at the first call).
void take_stdin(FirmwareRuntime& r);
/// The runtime interrupt attachInterrupt made for `interrupt_number`, or -1.
int irq_of_interrupt(int interrupt_number);

}  // namespace l6470emu::arduino
