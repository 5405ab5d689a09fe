// The `serve` and `ctl` subcommands: run the emulator as a daemon that unmodified programs
// reach through libl6470emu-preload.so, and talk to it (the physical world, inspection).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace l6470emu {

/// Registers `serve` and `ctl` on `app`; after parsing, run() executes whichever was chosen.
class ServeCommands {
 public:
  explicit ServeCommands(CLI::App& app);
  /// The exit status of the chosen subcommand, or nothing when neither was chosen.
  std::optional<int> run();

 private:
  CLI::App* serve_ = nullptr;
  CLI::App* ctl_ = nullptr;
  std::string chain_;
  std::string config_file_;
  std::string socket_;
  double time_scale_ = 0;
  bool virtual_time_ = false;
  std::string log_;
  std::string record_;
  std::string coverage_;
  bool cuse_ = false;
  bool uhid_ = false;
  std::string node_owner_ = "root";
  std::string node_group_ = "root";
  std::string node_mode_ = "0660";
  std::string serve_number_from_;  // serve --number-from (overrides numbering=)
  std::string check_;              // serve --check (overrides check=)
  std::string check_allow_;        // serve --check-allow (overrides check.allow=)
  std::string ctl_number_from_;    // ctl --number-from before the command word
  std::string command_word_;  // the ctl command; its arguments come from remaining()
};

}  // namespace l6470emu
