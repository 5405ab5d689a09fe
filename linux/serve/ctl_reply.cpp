// ctl's reading of a reply: status bounds, refusals, terminal-safe text.
#include "linux/serve/ctl_reply.hpp"

#include <cerrno>
#include <cstring>

#include "linux/protocol.hpp"
#include "linux/terminal_text.hpp"

namespace l6470emu {

CtlOutcome decode_ctl_reply(std::span<const std::uint8_t> reply, const std::string& socket_path) {
  CtlOutcome o;
  const std::string where = terminal_safe(socket_path);
  ReplyHeader h;
  if (reply.size() < sizeof h) {
    o.on_stderr = true;
    o.text = "l6470emu ctl: the daemon at " + where + " sent a reply of " + std::to_string(reply.size()) +
             " bytes, shorter than a reply header\n";
    return o;
  }
  if (const auto why = decode_refusal(reply)) {
    o.on_stderr = true;
    o.text = "l6470emu ctl: the daemon at " + where + " refused the connection: " + terminal_safe(*why) + "\n";
    return o;
  }
  std::memcpy(&h, reply.data(), sizeof h);
  std::string text = terminal_safe(
      std::string_view(reinterpret_cast<const char*>(reply.data()) + sizeof h, reply.size() - sizeof h));
  if (!text.empty() && text.back() != '\n') text += '\n';
  if (h.result < 0 && h.result >= -4095) {
    o.text = text + "l6470emu ctl: the daemon at " + where + " did not carry out the command: " +
             std::strerror(static_cast<int>(-h.result)) + "\n";
  } else if (h.result < 0 || h.result > 2) {
    o.text = text + "l6470emu ctl: the daemon at " + where + " answered with status " + std::to_string(h.result) +
             " (a ctl status is 0, 1 or 2); taken as a failure\n";
  } else {
    o.status = static_cast<int>(h.result);
    o.text = std::move(text);
  }
  o.on_stderr = o.status != 0;
  return o;
}

}  // namespace l6470emu
