// The sketch preprocessor's lexer: what the first four translation phases of C++ leave of an
// .ino text, as far as finding its function definitions needs (firmware/sketch_prep.cpp). Not
// a preprocessor: no macro is expanded and no file included.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace l6470emu::sketch {

/// A token, or a mark where a conditional group (`#if`, `#ifdef X`, ... `#endif`) opens,
/// changes branch or closes. Only the branches kept get marks (see tokenize_sketch).
enum class TokenKind {
  Word,         ///< an identifier, a number, a punctuator, or a literal (its text then the quote alone)
  OpenGroup,    ///< the first branch kept of a group starts here
  OtherBranch,  ///< another branch kept of the same group starts here
  CloseGroup,   ///< the group's #endif (after a group with a branch kept)
};

struct Token {
  /// As the compiler reads it: backslash-newlines removed. A mark's is its directive on one line,
  /// comments left out, as it would open the branch kept: "#ifdef X", "#elif X > 1", "#else",
  /// "#endif"; the first branch kept of a group is given as an #if ("#elif X" as "#if X", an
  /// #else after skipped branches only as "#if 1").
  std::string text;
  std::size_t offset = 0;     ///< of its first character in the original text; a mark's is its '#'
  TokenKind kind = TokenKind::Word;
};

/// The tokens of `text`, in order: a UTF-8 byte-order mark at its start dropped (as the Arduino
/// builder drops it), lines joined at backslash-newline (translation phase 2), comments,
/// preprocessing directives and the inside of literals skipped, and the branches of conditional
/// groups that the compiler skips whatever the macros are left out: a branch whose condition is
/// a constant zero (`#if 0`, `#elif false`), and every branch after one whose condition is a
/// nonzero constant (`#if 1 ... #else`). The branches kept of a group stand between marks. Never
/// throws; unterminated constructs end at the end of the text.
std::vector<Token> tokenize_sketch(std::string_view text);

/// `text` without a UTF-8 byte-order mark at its start (the three bytes EF BB BF).
std::string_view without_bom(std::string_view text);

}  // namespace l6470emu::sketch
