// The sketch preprocessor's lexer (firmware/sketch_lexer_internal.hpp): the byte-order mark,
// line splicing, comments, literals and conditional groups whose condition is a constant.
#include "firmware/sketch_lexer_internal.hpp"

#include <algorithm>
#include <cctype>

namespace l6470emu::sketch {
namespace {

bool ident_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_' || (c & 0x80); }
bool ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || (c & 0x80); }
bool blank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f' || c == '\r'; }

// Translation phase 2: `text` with every backslash-newline removed (also with blanks or a CR
// between them, as GCC and Clang accept), and where each remaining character came from.
struct Spliced {
  std::string text;
  std::vector<std::size_t> origin;  // origin[i]: the offset in the original of text[i]; one more at the end
};

Spliced splice(std::string_view text, std::size_t from) {
  Spliced out;
  out.text.reserve(text.size() - from);
  out.origin.reserve(text.size() - from + 1);
  std::size_t i = from;
  while (i < text.size()) {
    if (text[i] == '\\') {
      std::size_t j = i + 1;
      while (j < text.size() && blank(text[j])) ++j;
      if (j < text.size() && text[j] == '\n') {
        i = j + 1;
        continue;
      }
    }
    out.text += text[i];
    out.origin.push_back(i);
    ++i;
  }
  out.origin.push_back(text.size());
  return out;
}

// Past the end of a quoted literal starting at `i` (on the quote); an unterminated one ends
// before the newline, which the compiler reads as the end of the line it is on.
std::size_t skip_quoted(std::string_view s, std::size_t i) {
  const char q = s[i++];
  while (i < s.size() && s[i] != q && s[i] != '\n') i += (s[i] == '\\' && i + 1 < s.size() && s[i + 1] != '\n') ? 2 : 1;
  return i < s.size() && s[i] == q ? i + 1 : i;
}

// Past the end of a raw string literal R"delim(...)delim" whose '"' is at `i`.
std::size_t skip_raw(std::string_view s, std::size_t i) {
  const std::size_t open = s.find('(', i);
  if (open == std::string_view::npos || open - i > 17) return skip_quoted(s, i);
  const std::string close = ")" + std::string(s.substr(i + 1, open - i - 1)) + "\"";
  const std::size_t end = s.find(close, open);
  return end == std::string_view::npos ? s.size() : end + close.size();
}

// Past a block comment whose "/*" is at `i`.
std::size_t skip_block_comment(std::string_view s, std::size_t i) {
  const std::size_t end = s.find("*/", i + 2);
  return end == std::string_view::npos ? s.size() : end + 2;
}

// A condition the lexer can decide without macros: a number or true/false, perhaps in parentheses.
enum class Condition { False, True, Undecided };

Condition evaluate(std::string_view c) {
  auto trim = [](std::string_view v) {
    while (!v.empty() && std::isspace(static_cast<unsigned char>(v.front()))) v.remove_prefix(1);
    while (!v.empty() && std::isspace(static_cast<unsigned char>(v.back()))) v.remove_suffix(1);
    return v;
  };
  c = trim(c);
  while (c.size() >= 2 && c.front() == '(' && c.back() == ')') c = trim(c.substr(1, c.size() - 2));
  if (c == "true") return Condition::True;
  if (c == "false") return Condition::False;
  while (!c.empty() && (c.back() == 'u' || c.back() == 'U' || c.back() == 'l' || c.back() == 'L')) c.remove_suffix(1);
  bool hex = false;
  if (c.size() > 2 && c[0] == '0' && (c[1] == 'x' || c[1] == 'X')) {
    c.remove_prefix(2);
    hex = true;
  }
  if (c.empty()) return Condition::Undecided;
  bool zero = true;
  for (const char d : c) {
    if (d == '\'') continue;  // a digit separator
    if (!(hex ? std::isxdigit(static_cast<unsigned char>(d)) : std::isdigit(static_cast<unsigned char>(d))))
      return Condition::Undecided;
    if (d != '0') zero = false;
  }
  return zero ? Condition::False : Condition::True;
}

// One #if ... #endif being read.
struct Group {
  bool outer_skipped = false;  // the group is itself inside a skipped branch
  bool taken = false;          // a branch before had a true constant condition: the rest are skipped
  bool skipped = false;        // the current branch
  bool marked = false;         // an OpenGroup mark was given
};

class Lexer {
 public:
  explicit Lexer(std::string_view original)
      : spliced_(splice(original, original.size() - without_bom(original).size())) {}

  std::vector<Token> run() {
    const std::string_view s = spliced_.text;
    bool line_start = true;  // only blanks and comments since the last newline: a '#' starts a directive
    std::size_t i = 0;
    while (i < s.size()) {
      const char c = s[i];
      if (c == '\n') {
        line_start = true;
        ++i;
        continue;
      }
      if (std::isspace(static_cast<unsigned char>(c))) {
        ++i;
        continue;
      }
      if (c == '/' && i + 1 < s.size() && s[i + 1] == '/') {
        i = std::min(s.size(), s.find('\n', i));
        continue;
      }
      if (c == '/' && i + 1 < s.size() && s[i + 1] == '*') {
        i = skip_block_comment(s, i);
        continue;
      }
      if (c == '#' && line_start) {
        i = directive(i);
        continue;
      }
      line_start = false;
      if (c == '"' || c == '\'') {
        emit(std::string(1, c), i);  // a literal: its text does not matter here
        i = skip_quoted(s, i);
        continue;
      }
      if (ident_start(c)) {
        std::size_t j = i;
        while (j < s.size() && ident_char(s[j])) ++j;
        const std::string_view word = s.substr(i, j - i);
        if (j < s.size() && s[j] == '"' &&
            (word == "R" || word == "u8R" || word == "uR" || word == "UR" || word == "LR")) {
          emit("\"", i);
          i = skip_raw(s, j);
          continue;
        }
        if (j < s.size() && (s[j] == '"' || s[j] == '\'') &&
            (word == "u8" || word == "u" || word == "U" || word == "L")) {
          emit(std::string(1, s[j]), i);
          i = skip_quoted(s, j);
          continue;
        }
        emit(std::string(word), i);
        i = j;
        continue;
      }
      if (std::isdigit(static_cast<unsigned char>(c))) {
        std::size_t j = i;
        while (j < s.size() && (ident_char(s[j]) || s[j] == '.' || s[j] == '\'')) ++j;
        emit(std::string(s.substr(i, j - i)), i);
        i = j;
        continue;
      }
      std::size_t len = 1;
      for (const std::string_view p : {"...", "::", "->", "&&", "||"})
        if (s.substr(i, p.size()) == p) {
          len = p.size();
          break;
        }
      emit(std::string(s.substr(i, len)), i);
      i += len;
    }
    return std::move(tokens_);
  }

 private:
  bool skipping() const { return !groups_.empty() && groups_.back().skipped; }

  void emit(std::string text, std::size_t at, TokenKind kind = TokenKind::Word) {
    if (skipping() && kind == TokenKind::Word) return;
    tokens_.push_back({std::move(text), spliced_.origin[at], kind});
  }

  // Reads the directive whose '#' is at `at` (to the end of its line, comments being blanks
  // and perhaps spanning lines) and returns where its line ends.
  std::size_t directive(std::size_t at) {
    const std::string_view s = spliced_.text;
    std::string line;
    std::size_t i = at + 1;
    while (i < s.size() && s[i] != '\n') {
      if (s[i] == '/' && i + 1 < s.size() && s[i + 1] == '/') {
        i = std::min(s.size(), s.find('\n', i));
        break;
      }
      if (s[i] == '/' && i + 1 < s.size() && s[i + 1] == '*') {
        i = skip_block_comment(s, i);
        line += ' ';
        continue;
      }
      if (s[i] == '"' || s[i] == '\'') {
        const std::size_t end = skip_quoted(s, i);
        line.append(s.substr(i, end - i));
        i = end;
        continue;
      }
      line += s[i++];
    }
    std::size_t n = 0;
    while (n < line.size() && std::isspace(static_cast<unsigned char>(line[n]))) ++n;
    std::size_t e = n;
    while (e < line.size() && ident_char(line[e])) ++e;
    const std::string name = line.substr(n, e - n);
    std::string_view rest = std::string_view(line).substr(e);
    while (!rest.empty() && std::isspace(static_cast<unsigned char>(rest.back()))) rest.remove_suffix(1);
    if (name == "if" || name == "ifdef" || name == "ifndef") {
      groups_.push_back({skipping()});
      branch(name == "if" ? evaluate(rest) : Condition::Undecided, name, rest, at);
    } else if (!groups_.empty() && (name == "elif" || name == "elifdef" || name == "elifndef")) {
      branch(name == "elif" ? evaluate(rest) : Condition::Undecided, name, rest, at);
    } else if (!groups_.empty() && name == "else") {
      branch(Condition::True, name, "", at);
    } else if (!groups_.empty() && name == "endif") {
      if (groups_.back().marked) emit("#endif", at, TokenKind::CloseGroup);
      groups_.pop_back();
    }
    return i;
  }

  // A branch of the innermost group begins at `at`, with the directive `name` `rest`.
  void branch(Condition condition, const std::string& name, std::string_view rest, std::size_t at) {
    Group& g = groups_.back();
    g.skipped = g.outer_skipped || g.taken || condition == Condition::False;
    if (g.skipped) return;
    g.taken = condition == Condition::True;
    if (g.marked) {
      emit("#" + name + std::string(rest), at, TokenKind::OtherBranch);
    } else {  // the first branch kept opens the group as the compiler sees it: #elif X as #if X
      const std::string opening = name == "else" ? "if 1" : name.substr(0, 4) == "elif" ? name.substr(2) : name;
      emit("#" + opening + std::string(rest), at, TokenKind::OpenGroup);
    }
    g.marked = true;
  }

  Spliced spliced_;
  std::vector<Group> groups_;
  std::vector<Token> tokens_;
};

}  // namespace

std::string_view without_bom(std::string_view text) {
  return text.substr(0, 3) == "\xEF\xBB\xBF" ? text.substr(3) : text;
}

std::vector<Token> tokenize_sketch(std::string_view text) { return Lexer(text).run(); }

}  // namespace l6470emu::sketch
