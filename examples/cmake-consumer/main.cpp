// Two daisy-chained L6470s in virtual time: chip 1 moves, chip 0 stays put.
#include <cstdio>
#include <l6470emu/daisychain/host.hpp>

int main() {
  l6470emu::Chain chain(2);
  l6470emu::ChainHost host(chain);  // one CS frame per byte, NOP to the other chip
  host.move(1, /*forward=*/true, 3200);
  host.wait_ms(500);
  const auto pos = host.get_param(1, l6470emu::Reg::ABS_POS);
  std::printf("chip 1 at %u, chip 0 at %u\n", pos, host.get_param(0, l6470emu::Reg::ABS_POS));
  return pos == 3200 ? 0 : 1;
}
