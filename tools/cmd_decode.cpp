// `l6470emu decode TRACE`: the explained log on standard output, a summary on standard error.
#include <unistd.h>

#include <exception>
#include <stdexcept>
#include <ostream>

#include "daisychain/chain_spec.hpp"
#include "core/counted.hpp"
#include "daisychain/decode.hpp"
#include "tools/progress.hpp"
#include "tools/trace_commands.hpp"

namespace l6470emu {

int run_decode(const DecodeArgs& args, std::ostream& out, std::ostream& err) {
  try {
    const NumberFrom number_from = number_from_option(args.number_from);
    const TraceFile file(args.trace.path, input_options(args.trace));
    const TraceWorld world = world_of(args.trace, file);
    Chain chain = world.make_chain();
    print_notes(file.header(), err);
    out << "# " << file.path() << " (" << file.header().format << "), chain " << world.summary() << " (" << world.how
        << "); " << describe_numbering(number_from) << "\n";
    if (world.overrides) out << "# " << world.override_note(file.path()) << "\n";
    DecodeOptions options;
    options.show_nops = args.nops;
    options.max_repeats = args.max_repeats;
    options.only_chip = args.chip;
    options.number_from = number_from;
    if (args.chip >= 0 && static_cast<std::size_t>(args.chip) >= chain.size())
      throw std::invalid_argument("--chip " + std::to_string(args.chip) + ": the chain has " +
                                  counted(chain.size(), "chip"));
    std::unique_ptr<TraceReader> reader = file.read();
    // The log goes to standard output: a bar on the terminal only when that is elsewhere.
    ProgressBar bar = isatty(STDOUT_FILENO) == 1 ? ProgressBar(err, false, "") : ProgressBar::on_stderr("decoding " + file.path());
    ProgressTraceReader watched(*reader, bar);
    const DecodeSummary s = decode_trace(watched, chain, out, options);
    bar.finish();
    out << "# " << counted(s.frames, "frame") << ", " << counted(s.commands, "command") << ", "
        << counted(s.answers, "answer") << ", " << counted(s.diagnostics, "diagnostic");
    if (s.suppressed) out << " (" << s.suppressed << " not shown: --max-repeats 0 shows all)";
    if (s.answer_mismatches)
      out << ", " << counted(s.answer_mismatches, "answer") << " the emulator would give differently (see replay)";
    out << "\n";
    if (s.divergence.found) {
      // Said at the end too, and by the exit status: the log after that point is a model.
      out << "# DIVERGED in " << s.frames_diverged << (s.frames_diverged == 1 ? " frame" : " frames");
      if (s.pins_diverged) out << " and " << s.pins_diverged << (s.pins_diverged == 1 ? " pin level" : " pin levels");
      out << ", first at " << s.divergence.summary << ": from there on the log is the emulator's model, not the trace\n";
      err << "l6470emu decode: the emulator does not reproduce " << file.path() << ": " << s.divergence.summary
          << (args.accept_divergence ? " (accepted: --accept-divergence)" : " (exit status 1; --accept-divergence accepts it)")
          << "\n";
      if (!args.accept_divergence) return kTraceDiverged;
    }
    return kTraceOk;
  } catch (const std::exception& e) {
    err << "l6470emu decode: " << e.what() << "\n";
    return kTraceBadInput;
  }
}

}  // namespace l6470emu
