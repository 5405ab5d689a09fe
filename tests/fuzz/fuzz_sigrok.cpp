// libFuzzer harness of the sigrok-cli JSON trace reader (spi/import_sigrok.cpp): a trace or
// one error line naming file:line (deep nesting included); what it reads goes through decode
// and replay.
#include "fuzz_support.hpp"

using namespace l6470emu;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  fuzz::run_reader(data, size, "fuzz.json", [](std::string_view text, const std::string& name) {
    return import_sigrok_json(text, name);
  }, TraceFormat::sigrok);
  return 0;
}
