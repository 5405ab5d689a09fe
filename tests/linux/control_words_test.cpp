// A ctl command line as words: what `l6470emu ctl` writes and the daemon reads back, so that a
// word with a blank in it stays one word and plain lines read as they always did.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "linux/serve/control_words.hpp"

namespace l6470emu {
namespace {

using Words = std::vector<std::string>;

TEST(ControlWords, PlainWordsAreJoinedByBlanksAndSplitBackAtBlanksAndTabs) {
  EXPECT_EQ(join_control_words({"status", "--chip", "1"}), "status --chip 1");
  EXPECT_EQ(split_control_words("  status \t--chip   1 "), (Words{"status", "--chip", "1"}));
  EXPECT_EQ(split_control_words(""), Words{});
  EXPECT_EQ(split_control_words("a\\b"), Words{"a\\b"});  // a backslash outside quotes is a character
}

TEST(ControlWords, AWordWithABlankAQuoteOrABackslashSurvivesTheRoundTrip) {
  const Words words{"trace", "start", "/tmp/my runs/run 1.bin", "say \"hi\"", "back\\slash", "", "tab\there"};
  const std::string line = join_control_words(words);
  EXPECT_EQ(line, "trace start \"/tmp/my runs/run 1.bin\" \"say \\\"hi\\\"\" \"back\\\\slash\" \"\" \"tab\there\"");
  EXPECT_EQ(split_control_words(line), words);
}

TEST(ControlWords, AnUnclosedQuoteEndsAtTheEndOfTheLine) {
  EXPECT_EQ(split_control_words("trace start \"run 1.bin"), (Words{"trace", "start", "run 1.bin"}));
  EXPECT_EQ(split_control_words("a\"b c\"d e"), (Words{"ab cd", "e"}));
}

}  // namespace
}  // namespace l6470emu
