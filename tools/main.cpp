// The l6470emu command-line program: subcommands over the emulator library.
#include <CLI/CLI.hpp>
#include <iostream>

#include "tools/demo.hpp"

int main(int argc, char** argv) {
  CLI::App app{"l6470emu: register-level emulator of the ST L6470-family SPI motion engines"};
  app.require_subcommand(1);

  std::size_t chips = 3;
  unsigned seconds = 10;
  auto* demo = app.add_subcommand("demo", "drive an emulated daisy chain and print what the chips did");
  demo->add_option("--chips", chips, "chips in the chain (1..256)")->check(CLI::Range(1, 256));
  demo->add_option("--seconds", seconds, "virtual seconds to run at most")->check(CLI::Range(1, 3600));

  CLI11_PARSE(app, argc, argv);
  if (*demo) return l6470emu::run_demo(chips, seconds, std::cout);
  return 0;
}
