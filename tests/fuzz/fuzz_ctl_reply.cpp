// libFuzzer harness of what `ctl` prints from a daemon's reply (linux/serve/ctl_reply.hpp), a
// server being any program that got to the socket first: whatever the packet, the exit status
// is 0, 1 or 2 and the text reaches the terminal with no control character but newline and tab,
// as valid UTF-8 without C1 controls, ending with a newline; terminal_safe is idempotent.
#include <string>
#include <string_view>

#include "fuzz_support.hpp"
#include "linux/serve/ctl_reply.hpp"
#include "linux/terminal_text.hpp"

using namespace l6470emu;

namespace {

/// Every byte a terminal could take as part of a control sequence is absent, and the text is
/// valid UTF-8 (so no byte can combine with the next one into a C1 control).
void check_terminal_safe(std::string_view t, const char* what) {
  for (std::size_t i = 0; i < t.size();) {
    const auto c = static_cast<unsigned char>(t[i]);
    FUZZ_CHECK(c != 0x7F && (c >= 0x20 || c == '\n' || c == '\t'), "%s: control byte 0x%02X at %zu", what, c, i);
    if (c < 0x80) {
      ++i;
      continue;
    }
    const std::size_t n = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 ? 2 : 0;
    FUZZ_CHECK(n > 0 && i + n <= t.size(), "%s: a byte 0x%02X that starts no UTF-8 sequence at %zu", what, c, i);
    for (std::size_t k = 1; k < n; ++k)
      FUZZ_CHECK((static_cast<unsigned char>(t[i + k]) & 0xC0) == 0x80, "%s: broken UTF-8 sequence at %zu", what, i);
    FUZZ_CHECK(!(c == 0xC2 && static_cast<unsigned char>(t[i + 1]) < 0xA0), "%s: a C1 control at %zu", what, i);
    i += n;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  const std::string_view raw(reinterpret_cast<const char*>(data), size);
  const std::string safe = terminal_safe(raw);
  check_terminal_safe(safe, "terminal_safe");
  FUZZ_CHECK(terminal_safe(safe) == safe, "terminal_safe is not idempotent");
  FUZZ_CHECK(safe.size() <= 4 * size, "terminal_safe made %zu bytes of %zu", safe.size(), size);

  const CtlOutcome o = decode_ctl_reply({data, size}, "/run/user/1000/l6470emu.sock");
  FUZZ_CHECK(o.status >= 0 && o.status <= 2, "exit status %d", o.status);
  FUZZ_CHECK(o.on_stderr == (o.status != 0), "status %d printed on %s", o.status, o.on_stderr ? "stderr" : "stdout");
  check_terminal_safe(o.text, "ctl's text");
  FUZZ_CHECK(o.text.empty() || o.text.back() == '\n', "ctl's text does not end with a newline");
  FUZZ_CHECK(o.text.size() <= 4 * size + 400, "ctl printed %zu bytes for a reply of %zu", o.text.size(), size);
  return 0;
}
