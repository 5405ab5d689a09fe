// The sketch preprocessor's lexer (firmware/sketch_lexer_internal.hpp): tokens as the compiler
// reads them after its first translation phases, at their offsets in the original text, and
// marks around the branches of conditional groups that reach the compiler.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "firmware/sketch_lexer_internal.hpp"

namespace l6470emu::test {
namespace {

using sketch::TokenKind;

// The tokens as one line: words spaced, an open group '<', another branch '|', a close '>'.
std::string shape(std::string_view text) {
  std::string out;
  for (const sketch::Token& t : sketch::tokenize_sketch(text)) {
    if (!out.empty()) out += ' ';
    switch (t.kind) {
      case TokenKind::Word:
        out += t.text;
        break;
      case TokenKind::OpenGroup:
        out += '<';
        break;
      case TokenKind::OtherBranch:
        out += '|';
        break;
      case TokenKind::CloseGroup:
        out += '>';
        break;
    }
  }
  return out;
}

TEST(SketchLexer, OffsetsPointIntoTheOriginalTextAcrossSplicesAndAByteOrderMark) {
  std::vector<std::pair<std::string, std::size_t>> seen;
  for (const sketch::Token& t : sketch::tokenize_sketch("\xEF\xBB\xBFint lo\\\nng_name;\n"))
    seen.emplace_back(t.text, t.offset);
  EXPECT_EQ(seen, (std::vector<std::pair<std::string, std::size_t>>{{"int", 3}, {"long_name", 7}, {";", 18}}));
}

TEST(SketchLexer, OnlyTheBranchesKeptAreMarkedAndSkippedOnesGiveNoTokens) {
  EXPECT_EQ(
      shape("#ifdef A\nx\n#else\ny\n#endif\n#if 0\nz {\n#elif B\nw\n#else\nv\n#endif\n#if 1\nu\n#else\nt\n#endif\n"),
      "< x | y > < w | v > < u >");
  const auto tokens = sketch::tokenize_sketch("a\n  #ifdef A\nb\n#endif\n");
  ASSERT_EQ(tokens.size(), 4u);
  EXPECT_EQ(tokens[1].offset, 4u);  // a mark is at its '#'
  EXPECT_EQ(tokens[3].offset, 15u);
}

TEST(SketchLexer, ADirectiveIsALogicalLineWhoseCommentsAreBlanks) {
  // Continued by backslash-newline, or by a block comment across lines; '#' after a comment
  // still starts a directive, after a token it does not.
  EXPECT_EQ(shape("#define BODY { \\\n }\n#if /* a\n */ 0\nx\n#endif\n/* c */ #if 0\ny\n#endif\nz # w\n"), "z # w");
}

TEST(SketchLexer, AnApostropheInASkippedGroupDoesNotHideItsEndif) {
  EXPECT_EQ(shape("#if 0\nit's an old note\n#endif\nvoid f() {}\n"), "void f ( ) { }");
  EXPECT_EQ(shape("#error it's not\nx\n"), "x");
}

TEST(SketchLexer, UnbalancedDirectivesEndWithoutACrash) {
  EXPECT_EQ(shape("#endif\n#else\nx\n#elif 1\n"), "x");
  EXPECT_EQ(shape("#ifdef A\nx\n#else\ny\n"), "< x | y");  // the compiler refuses it; the lexer just stops
  EXPECT_EQ(shape("#if 0\nx\n"), "");
}

}  // namespace
}  // namespace l6470emu::test
