// `l6470emu plot TRACE -o OUT.png`: runs python3 -m l6470emu.plot with the package on
// PYTHONPATH. The options are declared here too (for --help and the man page) but checked by
// the Python side, which reports every mistake in one line with exit status 2.
#include "tools/cmd_plot.hpp"

#include <glob.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <sys/stat.h>

#include "daisychain/motion_series.hpp"
#include "spi/trace.hpp"

namespace l6470emu {
namespace {

bool holds_package(const std::string& dir) {
  struct stat st{};
  return !dir.empty() && ::stat((dir + "/l6470emu/plot.py").c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string parent_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

}  // namespace

std::string python_package_dir(const std::string& exe) {
  if (const char* given = std::getenv("L6470EMU_PYTHONPATH"); given != nullptr && *given != '\0') return given;
  const std::string bin = parent_of(exe);
  // A build tree: build/l6470emu beside build/python/l6470emu.
  if (holds_package(bin + "/python")) return bin + "/python";
  // Installed: PREFIX/bin/l6470emu and PREFIX/lib/python3/dist-packages (/usr) or
  // PREFIX/lib/python3.X/dist-packages (any other prefix), as python/install_module.cmake.in puts it.
  const std::string prefix = parent_of(bin);
  if (holds_package(prefix + "/lib/python3/dist-packages")) return prefix + "/lib/python3/dist-packages";
  glob_t g{};
  std::string found;
  if (::glob((prefix + "/lib/python3.*/dist-packages").c_str(), 0, nullptr, &g) == 0)
    for (std::size_t i = g.gl_pathc; i-- > 0 && found.empty();)  // newest Python first
      if (holds_package(g.gl_pathv[i])) found = g.gl_pathv[i];
  ::globfree(&g);
  return found;
}

std::vector<std::string> plot_command(const std::vector<std::string>& args) {
  const char* python = std::getenv("L6470EMU_PYTHON");
  std::vector<std::string> cmd{python != nullptr && *python != '\0' ? python : "/usr/bin/python3", "-m",
                               "l6470emu.plot"};
  cmd.insert(cmd.end(), args.begin(), args.end());
  return cmd;
}

namespace {

struct PlotArgs {
  std::string trace, output, chips, from, to, chain, board, format, select, max_points, max_frames, title, size, dpi,
      number_from;
  bool accept_divergence = false;
};

[[noreturn]] void run_plot(const PlotArgs& a, const CLI::App& sub) {
  std::vector<std::string> args;
  if (!a.trace.empty()) args.push_back(a.trace);
  const std::pair<const char*, const std::string*> options[] = {
      {"--output", &a.output}, {"--chips", &a.chips},   {"--from", &a.from},   {"--to", &a.to},
      {"--chain", &a.chain},   {"--format", &a.format}, {"--select", &a.select}, {"--max-points", &a.max_points},
      {"--title", &a.title},   {"--size", &a.size},     {"--dpi", &a.dpi},     {"--number-from", &a.number_from},
      {"--max-frames", &a.max_frames}, {"--board", &a.board}};
  for (const auto& [name, value] : options)
    if (sub.count(name) > 0) args.push_back(std::string(name) + "=" + *value);
  if (a.accept_divergence) args.push_back("--accept-divergence");

  char exe[4096];
  const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof exe - 1);
  const std::string self = n > 0 ? std::string(exe, static_cast<std::size_t>(n)) : std::string();
  const std::string dir = python_package_dir(self);
  if (!dir.empty()) {
    const char* old = std::getenv("PYTHONPATH");
    const std::string path = old != nullptr && *old != '\0' ? dir + ":" + old : dir;
    ::setenv("PYTHONPATH", path.c_str(), 1);
  }
  const std::vector<std::string> cmd = plot_command(args);
  std::vector<char*> argv;
  for (const std::string& s : cmd) argv.push_back(const_cast<char*>(s.c_str()));
  argv.push_back(nullptr);
  std::cout.flush();
  ::execv(argv[0], argv.data());
  std::cerr << "l6470emu plot: cannot run " << cmd[0] << " (" << std::strerror(errno)
            << "): plotting needs Debian's python3 with python3-matplotlib (or set L6470EMU_PYTHON)\n";
  std::exit(2);
}

}  // namespace

void add_plot_command(CLI::App& app) {
  auto a = std::make_shared<PlotArgs>();
  CLI::App* p = app.add_subcommand(
      "plot", "draw each chip's position, speed, BUSY/FLAG/SW and commands against time (PNG or SVG), "
              "from a trace replayed through the emulator (needs python3-matplotlib; exit 1 = the emulator does not "
              "reproduce the trace, which the picture marks; 2 = bad input)");
  p->add_option("TRACE", a->trace, "trace file: native, Saleae CSV, umockdev .ioctl, ftrace text, sigrok JSON, VCD or .sr");
  p->add_option("-o,--output", a->output, "picture to write: .png or .svg");
  p->add_option("--chips", a->chips, "chips to draw: 0,2 or 1-3 (default all; numbered as --number-from says)");
  p->add_option("--number-from", a->number_from,
                "chip 0 is the chip driving MISO (miso, the default) or the one reading the host's MOSI (mosi)");
  p->add_option("--from", a->from, "window start, seconds from the trace's start (a capture's own clock counts from 0 here)");
  p->add_option("--to", a->to,
                "window end, seconds (default: the trace's end, plus up to 1 s while a move goes on, drawn 4% longer)");
  p->add_option("--chain", a->chain,
                "the emulated chain (3, 2*L6470,L6480), or the board description of one chain (\"chips=L6470 "
                "axis.0=stops=0..256000,switch=home@0\"); default: the trace's own");
  p->add_option("--board", a->board,
                "a file with the board description of one chain to run a capture through (replaces the trace's own; "
                "the picture says so)");
  p->add_flag("--accept-divergence", a->accept_divergence,
              "exit 0 even when the emulator does not reproduce the trace (the picture still marks where)");
  p->add_option("--format", a->format, "input format: native, saleae, umockdev, ftrace, sigrok, vcd (default: recognised)");
  p->add_option("--select", a->select, "the stream to take when the file has several");
  p->add_option("--max-points", a->max_points,
                "most samples per chip (default 4000, at most " + std::to_string(kMaxMotionPoints) + ")");
  p->add_option("--max-frames", a->max_frames,
                "the most frames the trace may hold, 'repeat' lines counted as the frames they stand for (default " +
                    std::to_string(kDefaultMaxTraceFrames) + "; 0 = no limit)");
  p->add_option("--title", a->title, "the picture's title (default: the file and the chain)");
  p->add_option("--size", a->size, "width x height in inches (default 10x7.5)");
  p->add_option("--dpi", a->dpi, "PNG resolution, and of the images an SVG embeds for dense series (default 100)");
  p->callback([a, p] { run_plot(*a, *p); });
}

}  // namespace l6470emu
