// libFuzzer harness of the umockdev SPI .ioctl reader (spi/import_umockdev.cpp): a trace or
// one error line naming file:line; what it reads goes through decode and replay.
#include "fuzz_support.hpp"

using namespace l6470emu;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  fuzz::run_reader(data, size, "fuzz.ioctl", [](std::string_view text, const std::string& name) {
    return import_umockdev_ioctl(text, name);
  }, TraceFormat::umockdev);
  return 0;
}
