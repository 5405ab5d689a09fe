// `l6470emu serve` and `l6470emu ctl`.
#include "tools/cmd_serve.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "board/coverage_file.hpp"
#include "linux/board_config_file.hpp"
#include "linux/device_paths.hpp"
#include "linux/serve/control.hpp"
#include "linux/serve/control_words.hpp"
#include "linux/serve/daemon.hpp"
#include "tools/install_paths.hpp"
#include "tools/output_check.hpp"
#include "tools/kernel_nodes.hpp"

namespace l6470emu {

ServeCommands::ServeCommands(CLI::App& app) {
  serve_ = app.add_subcommand("serve", "run an emulated board as a daemon for unmodified programs (LD_PRELOAD)");
  serve_->add_option("--chain", chain_,
                     "the board, as in L6470EMU_CHAIN: 'bus=0 cs=0 chips=3xL6470[ gpiochip=N]; ...' "
                     "(default: bus=0 cs=0 chips=L6470)");
  serve_->add_option("--config", config_file_, "read the board from this file instead (one clause per line)");
  serve_->add_option("--socket", socket_, "Unix socket to serve on (default $L6470EMU_SOCKET, "
                                          "$XDG_RUNTIME_DIR/l6470emu.sock or /tmp/l6470emu-UID.sock)");
  serve_->add_option("--time-scale", time_scale_, "virtual seconds per wall-clock second (default 1)")
      ->check(CLI::Range(1e-6, 1e6));
  serve_->add_flag("--virtual-time", virtual_time_,
                   "time moves only with bus traffic and `ctl advance` (deterministic runs)");
  serve_->add_option("--log", log_, "diagnostics: stderr (default), off, or a file");
  serve_->add_option("--coverage", coverage_,
                     "collect interface coverage and merge it into this file when the daemon stops (docs/coverage.md)");
  serve_->add_option("--record", record_,
                     "record every chain into this native trace, flushed frame by frame "
                     "(several chains: the chain's name goes before the extension)");

  serve_->add_option("--number-from", serve_number_from_,
                     "which end chip 0 is at in diagnostics and ctl: miso (chip 0 drives MISO) or mosi (chip 0 reads "
                     "the host's MOSI); default the board's numbering=, else miso");
  serve_->add_option("--check", check_,
                     "the driver sanitizer: off, warn (a log line per broken rule of the chip) or error (a client that "
                     "breaks one exits with status 86 and the report); default the board's check=, else warn");
  serve_->add_option("--check-allow", check_allow_,
                     "rules the sanitizer lets pass, comma separated; default the board's check.allow=");
  serve_->add_flag("--cuse", cuse_,
                   "also serve each chain as a real character device /dev/spidevB.C through CUSE "
                   "(root; modprobe cuse), for every program, static or not");
  serve_->add_flag("--uhid", uhid_,
                   "also put each chip's BUSY, FLAG, SW, STCK, STBY_RST on a real gpiochip: one emulated "
                   "CP2112 USB bridge per chip through /dev/uhid (root; modprobe uhid hid-cp2112)");
  serve_->add_option("--node-owner", node_owner_, "owner of the kernel nodes (user name or id; default root)");
  serve_->add_option("--node-group", node_group_, "group of the kernel nodes (default root; `spi`, `gpio` as on a Raspberry Pi)");
  serve_->add_option("--node-mode", node_mode_, "mode of the kernel nodes, octal (default 0660)");

  ctl_ = app.add_subcommand("ctl", "control a running daemon: " + std::string("status, get, dump, sw, pin, fault, adc, "
                                                                               "time, advance, chains, trace (ctl help)"));
  ctl_->add_option("--socket", socket_, "the daemon's socket (default as for serve)");
  ctl_->add_option("--number-from", ctl_number_from_,
                   "count chips from the miso or the mosi end for this command (default: the daemon's numbering=)");
  // Only the command word is parsed here; everything after it (--chip K, --chain NAME, values)
  // goes to the daemon untouched, in order.
  ctl_->add_option("command", command_word_, "the command (its arguments follow it)")->required();
  ctl_->prefix_command();
}

std::optional<int> ServeCommands::run() {
  if (serve_ && *serve_) {
    ParseResult parsed;
    if (!config_file_.empty() && !chain_.empty()) {
      std::cerr << "l6470emu serve: give --chain or --config, not both\n";
      return 2;
    }
    if (!config_file_.empty())
      parsed = load_board_config_file(config_file_);
    else
      parsed = parse_board_config(chain_.empty() ? "bus=0 cs=0 chips=L6470" : chain_, "--chain");
    if (parsed.config)  // a node path this machine already uses for something else is refused too
      parsed.error.message = check_device_paths(*parsed.config, config_file_.empty() ? "--chain" : config_file_);
    if (!parsed.config || !parsed.error.message.empty()) {
      std::cerr << parsed.error.message << "\n";
      return 2;
    }
    BoardConfig config = *parsed.config;
    if (config.chains.empty()) {
      std::cerr << "l6470emu serve: the board has no chain\n";
      return 2;
    }
    if (time_scale_ > 0) config.time.scale = time_scale_;
    if (virtual_time_) config.time.virtual_time = true;
    if (!log_.empty()) config.log = log_;
    if (!record_.empty()) config.trace = record_;
    if (serve_->count("--coverage") > 0) {
      if (const std::string why = check_coverage_output(coverage_); !why.empty()) {
        std::cerr << "l6470emu serve: --coverage: " << why << "\n";
        return 2;
      }
      config.coverage = absolute_path(coverage_);
    }
    if (!serve_number_from_.empty()) {
      const auto from = number_from_named(serve_number_from_);
      if (!from) {
        std::cerr << "l6470emu serve: --number-from must be miso (chip 0 drives MISO) or mosi (chip 0 reads the host's "
                     "MOSI), not '"
                  << shown_text(serve_number_from_) << "'\n";
        return 2;
      }
      config.numbering = *from;
    }
    // The sanitizer: --check and --check-allow over the description's check= and check.allow=.
    const std::string& level = check_;
    const std::string& allow = check_allow_;
    std::string why;
    if (!level.empty()) {
      const auto l = parse_check_level(level, why);
      if (!l) {
        std::cerr << "l6470emu serve: --check " << why << "\n";
        return 2;
      }
      config.check.level = *l;
    }
    if (!allow.empty()) {
      const auto rules = parse_rule_list(allow, why);
      if (!rules) {
        std::cerr << "l6470emu serve: --check-allow " << why << "\n";
        return 2;
      }
      config.check.allowed = *rules;
    }
    const std::string socket = !socket_.empty() ? socket_ : !config.socket.empty() ? config.socket : default_socket_path();
    FrontEnds front_ends;
    if (cuse_ || uhid_) {
      NodeAccess access;
      if (const std::string error = parse_node_access(node_owner_, node_group_, node_mode_, access); !error.empty()) {
        std::cerr << "l6470emu serve: " << error << "\n";
        return 2;
      }
      front_ends = kernel_front_ends(cuse_, uhid_, access);
    }
    return run_daemon(config, socket, std::cout, std::cerr, front_ends, preload_library_path(own_program_path()));
  }
  if (ctl_ && *ctl_) {
    // A command no daemon knows is a usage error here, before any daemon is asked.
    const auto& known = control_commands();
    if (command_word_ != "--help" && std::find(known.begin(), known.end(), command_word_) == known.end()) {
      std::cerr << "l6470emu ctl: " << unknown_control_command(command_word_) << " (l6470emu ctl help)\n";
      return 2;
    }
    std::vector<std::string> all = {command_word_};
    for (const auto& extra : ctl_->remaining()) all.push_back(extra);
    if (!ctl_number_from_.empty()) {  // the daemon checks it, as when it follows the command
      all.push_back("--number-from");
      all.push_back(ctl_number_from_);
    }
    // The daemon runs elsewhere: a relative trace file is meant from here.
    if (all.size() >= 3 && all[0] == "trace" && all[1] == "start" && !all[2].empty() && all[2][0] != '/' && all[2][0] != '-')
      all[2] = absolute_path(all[2]);
    // A word with a blank in it (a trace file "run 1.bin") stays one word on the daemon's side.
    const std::string command = join_control_words(all);
    if (command == "help" || command == "--help") {
      // The daemon's help says how it numbers chips; without a daemon, the general text.
      std::ostringstream help, quiet;
      if (run_ctl(socket_.empty() ? default_socket_path() : socket_, "help", help, quiet) == 0)
        std::cout << help.str();
      else
        std::cout << control_help();
      return 0;
    }
    return run_ctl(socket_.empty() ? default_socket_path() : socket_, command, std::cout, std::cerr);
  }
  return std::nullopt;
}

}  // namespace l6470emu
