// The program's standard input as Serial input: read whole (up to EOF, at most 1 MiB) at the
// first Serial read, through stdio, so that it has all arrived at the start and runs stay
// deterministic. A terminal is read the same way: the run waits for Ctrl-D.
#include <algorithm>
#include <cstdio>
#include <string_view>

#include "firmware/arduino/arduino_internal.hpp"

namespace l6470emu::arduino {

void take_stdin(FirmwareRuntime& r) {
  static bool taken = false;
  if (taken) return;
  taken = true;
  constexpr std::size_t kMaxStdinBytes = std::size_t{1} << 20;
  std::size_t total = 0;
  char buf[4096];
  while (total < kMaxStdinBytes) {
    const std::size_t n = std::fread(buf, 1, std::min(sizeof buf, kMaxStdinBytes - total), stdin);
    if (n == 0) break;
    r.serial_arrive(std::string_view(buf, n));
    total += n;
  }
  if (total == kMaxStdinBytes && std::fgetc(stdin) != EOF)
    r.log("standard input: only its first 1 MiB reaches Serial (the rest is not read)");
}

}  // namespace l6470emu::arduino
