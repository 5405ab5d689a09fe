// A board description parsed for a test: the config, with the parser's message as a test failure
// when it refuses the text. Header-only.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "board/board_config.hpp"

namespace l6470emu::test {

/// `text` parsed as a board description (source name "test"); a refusal fails the test with the
/// parser's message. Meant for descriptions the test knows are good.
inline BoardConfig config_of(const std::string& text) {
  ParseResult p = parse_board_config(text, "test");
  EXPECT_TRUE(p.config) << p.error.message;
  return *p.config;
}

}  // namespace l6470emu::test
