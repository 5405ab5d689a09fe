// libFuzzer harness of the Linux ftrace reader (spi/import_ftrace.cpp) in each of its four
// framings: a trace or one error line naming file:line; what it reads goes through decode
// and replay.
#include "fuzz_support.hpp"

using namespace l6470emu;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  for (FtraceFraming framing :
       {FtraceFraming::automatic, FtraceFraming::cs, FtraceFraming::transfer, FtraceFraming::message}) {
    ImportOptions options;
    options.ftrace_framing = framing;
    fuzz::run_reader(
        data, size, "fuzz.txt",
        [&options](std::string_view text, const std::string& name) { return import_ftrace(text, name, options); },
        TraceFormat::ftrace, options);
  }
  return 0;
}
