// Reading a board description file: at most kMaxConfigBytes + 1 bytes through
// spi/input_file.hpp (a device is refused before it is opened, a FIFO waited for a bounded
// time), then board/board_config.cpp's parser.
#include "linux/board_config_file.hpp"

#include <optional>
#include <string>

#include "spi/input_file.hpp"

namespace l6470emu {

ParseResult load_board_config_file(const std::string& path) {
  const std::string where = "l6470emu: config file " + shown_text(path, 200) + ": ";
  auto failed = [&](const std::string& what) { return ParseResult{std::nullopt, {where + what}}; };
  // A FIFO (a shell's <(...)) is fine once its writer writes; a device, a directory or a FIFO
  // nobody writes to is refused (spi/input_file.hpp).
  std::string why;
  const std::optional<std::string> text = read_input_file(path, kMaxConfigBytes, why);
  if (!text) return failed(why + (why == "is a directory" ? " (give the board description file)" : ""));
  if (text->size() > kMaxConfigBytes)
    return failed("longer than 1 MiB (a board description is a few lines: is this the right file?)");
  return parse_board_config(*text, path);
}

}  // namespace l6470emu
