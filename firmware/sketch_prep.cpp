// The sketch preprocessor: a small C++ tokenizer (comments, strings, character and raw string
// literals and preprocessor lines skipped) that finds function definitions at file level.
#include "firmware/sketch_prep.hpp"

#include <algorithm>
#include <cctype>
#include <cstddef>

namespace l6470emu {
namespace {

struct Token {
  std::string text;
  std::size_t offset = 0;  // of its first character
};

bool ident_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_' || (c & 0x80); }
bool ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || (c & 0x80); }

// Past the end of a quoted literal starting at `i` (on the quote).
std::size_t skip_quoted(std::string_view s, std::size_t i) {
  const char q = s[i++];
  while (i < s.size() && s[i] != q && s[i] != '\n') i += s[i] == '\\' ? 2 : 1;
  return std::min(s.size(), i + 1);
}

// Past the end of a raw string literal R"delim(...)delim" whose '"' is at `i`.
std::size_t skip_raw(std::string_view s, std::size_t i) {
  const std::size_t open = s.find('(', i);
  if (open == std::string_view::npos || open - i > 17) return skip_quoted(s, i);
  const std::string close = ")" + std::string(s.substr(i + 1, open - i - 1)) + "\"";
  const std::size_t end = s.find(close, open);
  return end == std::string_view::npos ? s.size() : end + close.size();
}

std::vector<Token> tokenize(std::string_view s) {
  std::vector<Token> tokens;
  bool line_start = true;  // only blanks since the last newline: a '#' starts a directive
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
      while (i < s.size() && s[i] != '\n') i += (s[i] == '\\' && i + 1 < s.size() && s[i + 1] == '\n') ? 2 : 1;
      continue;
    }
    if (c == '/' && i + 1 < s.size() && s[i + 1] == '*') {
      const std::size_t end = s.find("*/", i + 2);
      i = end == std::string_view::npos ? s.size() : end + 2;
      continue;
    }
    if (c == '#' && line_start) {
      // A directive runs to the end of its logical line (backslash-newline continues it).
      while (i < s.size() && s[i] != '\n') {
        if (s[i] == '\\' && i + 1 < s.size() && s[i + 1] == '\n') ++i;
        ++i;
      }
      continue;
    }
    line_start = false;
    if (c == '"' || c == '\'') {
      tokens.push_back({std::string(1, c), i});  // a literal: its text does not matter here
      i = skip_quoted(s, i);
      continue;
    }
    if (ident_start(c)) {
      std::size_t j = i;
      while (j < s.size() && ident_char(s[j])) ++j;
      const std::string_view word = s.substr(i, j - i);
      if (j < s.size() && s[j] == '"' && (word == "R" || word == "u8R" || word == "uR" || word == "UR" || word == "LR")) {
        tokens.push_back({"\"", i});
        i = skip_raw(s, j);
        continue;
      }
      if (j < s.size() && (s[j] == '"' || s[j] == '\'') && (word == "u8" || word == "u" || word == "U" || word == "L")) {
        tokens.push_back({std::string(1, s[j]), i});
        i = skip_quoted(s, j);
        continue;
      }
      tokens.push_back({std::string(word), i});
      i = j;
      continue;
    }
    if (std::isdigit(static_cast<unsigned char>(c))) {
      std::size_t j = i;
      while (j < s.size() && (ident_char(s[j]) || s[j] == '.' || s[j] == '\'')) ++j;
      tokens.push_back({std::string(s.substr(i, j - i)), i});
      i = j;
      continue;
    }
    for (const std::string_view p : {"...", "::", "->", "&&", "||"}) {
      if (s.substr(i, p.size()) == p) {
        tokens.push_back({std::string(p), i});
        i += p.size();
        goto next;
      }
    }
    tokens.push_back({std::string(1, c), i});
    ++i;
  next:;
  }
  return tokens;
}

bool is_keyword_start(const std::string& t) {
  static const char* const kWords[] = {"struct", "class", "union", "enum", "namespace", "typedef", "template",
                                       "using", "extern", "return", "if", "while", "for", "switch", "do", "else",
                                       "case", "default", "goto", "operator", "friend", "static_assert"};
  return std::find(std::begin(kWords), std::end(kWords), t) != std::end(kWords);
}

struct Definition {
  std::string prototype;
  std::size_t offset = 0;  // where its statement starts
};

std::vector<Definition> find_definitions(std::string_view text) {
  const std::vector<Token> tokens = tokenize(text);
  std::vector<Definition> found;
  int depth = 0;            // braces
  int parens = 0;           // parentheses and brackets at brace depth 0
  std::size_t start = 0;    // the first token of the statement at depth 0
  for (std::size_t k = 0; k < tokens.size(); ++k) {
    const std::string& t = tokens[k].text;
    if (depth > 0) {
      if (t == "{") ++depth;
      if (t == "}" && --depth == 0) start = k + 1;
      continue;
    }
    if (t == "(" || t == "[") ++parens;
    if ((t == ")" || t == "]") && parens > 0) --parens;
    if (parens > 0) continue;
    if (t == ";") {
      start = k + 1;
      continue;
    }
    if (t == "}") {  // a stray brace: resynchronise
      start = k + 1;
      continue;
    }
    if (t != "{") continue;
    ++depth;
    // tokens[start, k) is what stands before this brace.
    if (k == start) continue;
    bool plain = true;
    for (std::size_t j = start; j < k; ++j)
      if (is_keyword_start(tokens[j].text) || tokens[j].text == "=" || tokens[j].text == "\"") plain = false;
    if (!plain) continue;
    // The parameter list: the last ')' before the brace (after it only noexcept/const may stand).
    std::size_t close = k;
    while (close > start && tokens[close - 1].text != ")") {
      const std::string& after = tokens[close - 1].text;
      if (after != "noexcept" && after != "const") break;
      --close;
    }
    if (close == start || tokens[close - 1].text != ")") continue;
    const std::size_t close_paren = close - 1;
    int level = 0;
    std::size_t open = close_paren + 1;
    bool defaults = false;
    for (std::size_t j = close_paren + 1; j-- > start;) {
      if (tokens[j].text == ")") ++level;
      if (tokens[j].text == "(" && --level == 0) {
        open = j;
        break;
      }
      if (tokens[j].text == "=" && level == 1) defaults = true;
    }
    if (open > close_paren || open == start || defaults) continue;
    const std::string& name = tokens[open - 1].text;
    if (!ident_start(name[0]) || open - 1 == start) continue;  // no return type: a macro call such as ISR(...)
    if (open >= 2 && tokens[open - 2].text == "::") continue;  // A::f: a member defined outside its class
    // The tokens joined, spaced as people write them: "static unsigned long *at(const char *s)".
    auto glue_before = [](const std::string& w) { return w == "(" || w == ")" || w == "," || w == "[" || w == "]" || w == "::"; };
    auto glue_after = [](const std::string& w) { return w == "(" || w == "[" || w == "*" || w == "&" || w == "&&" || w == "::"; };
    std::string proto = tokens[start].text;
    for (std::size_t j = start + 1; j <= close_paren; ++j) {
      if (!glue_before(tokens[j].text) && !glue_after(tokens[j - 1].text)) proto += ' ';
      proto += tokens[j].text;
    }
    found.push_back({proto + ";", tokens[start].offset});
  }
  return found;
}

// The line (1-based) of `offset` in `text`.
std::size_t line_of(std::string_view text, std::size_t offset) {
  return 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(offset), '\n'));
}

std::string quoted(const std::string& path) {
  std::string out = "\"";
  for (const char c : path) {
    if (c == '"' || c == '\\') out += '\\';
    out += c == '\n' ? ' ' : c;
  }
  return out + "\"";
}

}  // namespace

std::vector<std::string> sketch_prototypes(std::string_view text) {
  std::vector<std::string> out;
  for (const Definition& d : find_definitions(text)) out.push_back(d.prototype);
  return out;
}

std::string prepare_sketch(const std::vector<SketchFile>& files) {
  // The files joined, each announced by a #line directive (which the tokenizer skips).
  std::string joined;
  struct Segment {
    std::size_t begin = 0;  // of the file's text in `joined`
    const SketchFile* file = nullptr;
  };
  std::vector<Segment> segments;
  for (const SketchFile& f : files) {
    joined += "#line 1 " + quoted(f.path) + "\n";
    segments.push_back({joined.size(), &f});
    joined += f.text;
    if (joined.empty() || joined.back() != '\n') joined += '\n';
  }
  const std::vector<Definition> defs = find_definitions(joined);
  std::string out = "#include <Arduino.h>\n";
  if (defs.empty()) return out + joined;
  // Insert before the first definition, at the start of its line when only blanks precede it.
  std::size_t at = defs.front().offset;
  const std::size_t line_begin = joined.rfind('\n', at == 0 ? 0 : at - 1);
  const std::size_t bol = line_begin == std::string::npos ? 0 : line_begin + 1;
  bool blank_before = true;
  for (std::size_t i = bol; i < at; ++i)
    if (!std::isspace(static_cast<unsigned char>(joined[i]))) blank_before = false;
  std::string insertion = blank_before ? "" : "\n";
  if (blank_before) at = bol;
  for (const Definition& d : defs) insertion += d.prototype + "\n";
  const Segment* seg = &segments.front();
  for (const Segment& s : segments)
    if (s.begin <= at) seg = &s;
  const std::size_t line = line_of(std::string_view(joined).substr(seg->begin), at - seg->begin);
  insertion += "#line " + std::to_string(line) + " " + quoted(seg->file->path) + "\n";
  return out + joined.substr(0, at) + insertion + joined.substr(at);
}

}  // namespace l6470emu
