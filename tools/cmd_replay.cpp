// `l6470emu replay TRACE`: the trace through the emulated chain, divergence reports on
// standard output as they are found, a summary line at the end.
#include <exception>
#include <ostream>

#include "daisychain/chain_spec.hpp"
#include "core/counted.hpp"
#include "daisychain/replay.hpp"
#include "tools/progress.hpp"
#include "tools/trace_commands.hpp"

namespace l6470emu {

int run_replay(const ReplayArgs& args, std::ostream& out, std::ostream& err) {
  try {
    const NumberFrom number_from = number_from_option(args.number_from);
    const TraceFile file(args.trace.path, input_options(args.trace));
    const TraceWorld world = world_of(args.trace, file);
    Chain chain = world.make_chain();
    print_notes(file.header(), err);
    err << "l6470emu: replaying " << file.path() << " through " << world.summary() << " (" << world.how << ")\n";
    if (world.overrides) {
      err << "note: " << world.override_note(file.path()) << "\n";
      out << "# " << world.override_note(file.path()) << "\n";
    }

    ReplayOptions options;
    options.keep_going = args.keep_going;
    options.max_reports = args.max_reports;
    options.compare_pins = !args.no_pins;
    options.number_from = number_from;
    std::unique_ptr<TraceReader> reader = file.read();
    ProgressBar bar = ProgressBar::on_stderr("replaying " + file.path());
    ProgressTraceReader watched(*reader, bar);
    bool numbering_said = false;
    const ReplayResult r = replay_trace(watched, chain, options, [&](const Divergence& d) {
      bar.clear();
      // The reports name chips: say once, before the first, how they are numbered.
      if (!numbering_said) out << "# " << describe_numbering(number_from) << "\n";
      numbering_said = true;
      out << (args.quiet ? d.summary : d.report) << "\n";
    });
    bar.finish();

    out << file.path() << ": " << counted(r.frames, "frame") << ", " << counted(r.bytes_compared, "MISO byte") << " compared";
    if (r.bytes_unknown) out << " (" << r.bytes_unknown << " not captured)";
    if (r.pin_checks) out << ", " << r.pin_checks << " pin levels checked (BUSY, FLAG, SW the axis drove)";
    if (r.matched()) {
      out << ": matched\n";
      return kTraceOk;
    }
    if (r.stopped_early) {
      out << ": DIVERGED (stopped at the first divergence; --continue reports them all)\n";
    } else {
      out << ": DIVERGED in " << counted(r.divergent_frames, "frame");
      if (r.pin_mismatches) out << " and " << counted(r.pin_mismatches, "pin level");
      if (r.divergences.size() < r.divergent_frames + r.pin_mismatches)
        out << " (" << r.divergences.size() << " reported; --max-reports)";
      out << "\n";
    }
    return kTraceDiverged;
  } catch (const std::exception& e) {
    err << "l6470emu replay: " << e.what() << "\n";
    return kTraceBadInput;
  }
}

}  // namespace l6470emu
