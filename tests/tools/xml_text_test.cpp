// XML text for the JUnit reports: markup escaped, control characters and bytes that are not
// UTF-8 never reach the file.
#include <gtest/gtest.h>

#include "tools/xml_text.hpp"

namespace l6470emu::test {
namespace {

TEST(XmlText, MarkupIsEscapedAndUtf8KeptAsItIs) {
  EXPECT_EQ(xml_text("a<b & \"c\" 'd'>"), "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;");
  EXPECT_EQ(xml_text("1 µs ± 2 → 3 \xF0\x9F\x98\x80"), "1 µs ± 2 → 3 \xF0\x9F\x98\x80");
  EXPECT_EQ(xml_text("line\nnext\ttab"), "line\nnext\ttab");
}

TEST(XmlText, ControlCharactersBecomeSpacesAndBrokenUtf8TheReplacementCharacter) {
  EXPECT_EQ(xml_text(std::string("a\x01" "b\x1b" "c", 5)), "a b c");
  EXPECT_EQ(xml_text("\xFF"), "\xEF\xBF\xBD");
  EXPECT_EQ(xml_text("\xC3"), "\xEF\xBF\xBD");            // cut short
  EXPECT_EQ(xml_text("\xC0\xAF"), "\xEF\xBF\xBD\xEF\xBF\xBD");  // overlong '/'
  EXPECT_EQ(xml_text("\xED\xA0\x80"), "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD");  // a surrogate
  EXPECT_EQ(xml_text("ok\xE2\x82"), "ok\xEF\xBF\xBD\xEF\xBF\xBD");
}

}  // namespace
}  // namespace l6470emu::test
