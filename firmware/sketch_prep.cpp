// The sketch preprocessor: finds the function definitions at file level in the tokens of the
// lexer (firmware/sketch_lexer_internal.hpp) and writes their prototypes before the first one
// outside every conditional group (before the first of all when there is none, as in a sketch
// inside an include guard).
//
// Why a lexer of our own and not the Arduino builder's pipeline (the joined sketch through the
// compiler's -E, Universal Ctags listing the definitions of its output, the prototypes put into
// the original text): for someone who builds sketches in CI, that pipeline would make
// universal-ctags a build dependency of every project using l6470emu_add_sketch, installed
// package included, and l6470emu-ino would need the target's compiler, include directories and
// definitions before the target compiles, and start two programs per sketch (tens of milliseconds
// of CPU, more on a loaded machine, where this takes microseconds); its result would hang on a
// program that libFuzzer cannot run in-process, so what decides which prototypes exist would go
// unfuzzed. What the three failures of issue 35 needed from the compiler is the part of
// translation phases 1-4 that is fully specified without the macros: the byte-order mark
// (dropped, as arduino-cli drops it), backslash-newline (spliced before lexing, so signatures and
// identifiers join as the compiler joins them) and conditional groups whose condition is a
// constant (`#if 0`: skipped, so an unbalanced brace there counts for nothing and no prototype or
// #line lands inside it). Groups on macros (`#ifdef ESP32`) are what only the compiler can
// decide. Each of their branches is read from the brace depth the group began at, the first
// branch's depth going on after #endif; a function inside one gets its prototype inside the same
// conditions, written again around it; and the prototypes go before the first function outside
// every group, so that a group the compiler leaves out takes none of them with it (and the #line
// after them stays outside it). What differs from arduino-cli, which sees only the branch
// compiled: the conditions are evaluated where the prototypes stand, not where the function is (a
// macro defined in between counts differently); a function whose signature is only partly inside
// a group gets no prototype; and a function in a group above the first one outside every group is
// not declared before calls it makes to later ones.
#include "firmware/sketch_prep.hpp"

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <optional>

#include "firmware/sketch_lexer_internal.hpp"

namespace l6470emu {
namespace {

using sketch::Token;
using sketch::TokenKind;

bool is_keyword_start(const std::string& t) {
  static const char* const kWords[] = {"struct", "class", "union", "enum", "namespace", "typedef", "template",
                                       "using", "extern", "return", "if", "while", "for", "switch", "do", "else",
                                       "case", "default", "goto", "operator", "friend", "static_assert"};
  return std::find(std::begin(kWords), std::end(kWords), t) != std::end(kWords);
}

constexpr std::size_t kNone = static_cast<std::size_t>(-1);

struct Definition {
  std::string prototype;
  std::size_t offset = 0;  // of its first token
  std::size_t branch = 0;  // the branch of a conditional group it is in (Branch), or kNone
};

// A branch kept of a conditional group, in the tree the groups make.
struct Branch {
  std::size_t parent = 0;  // the branch the group is in, or kNone at file level
  std::size_t before = 0;  // the branch kept before it in the same group, or kNone for the first
  std::size_t token = 0;   // its mark (the directive's text)
  std::size_t depth = 0;   // 1 for a group at file level
  std::size_t group = 0;   // its group's first branch kept
};

// The definitions found in a text and what their prototypes' conditions are made of.
struct Found {
  std::vector<Token> tokens;
  std::vector<Branch> branches;
  std::vector<Definition> definitions;
};

// The statements being read share their beginnings (the text before a group is the beginning
// of each of its branches): each is a chain of links back to its first token, so that keeping
// the reading at a group's #if costs nothing, whatever the length of the statement.
struct Link {
  std::size_t token = 0;  // index in the tokens
  std::size_t before = 0;  // the link of the token before, or kNone
};
// No signature is this long; a longer statement gets no prototype, so that reading one costs at
// most this much per brace whatever the input.
constexpr std::size_t kMaxSignatureTokens = 1024;

// Where the reading of the tokens at file level stands.
struct Reading {
  int depth = 0;                 // braces
  int parens = 0;                // parentheses and brackets at brace depth 0
  std::size_t last = kNone;      // the statement at depth 0 so far: its last link
  std::size_t length = 0;        // and its number of tokens
  std::size_t begins_at = 0;     // its first token's offset
  std::size_t level = 0;         // the groups open when it began
  bool conditional = false;      // part of it is inside a group it outlived: its text depends on macros
  bool empty() const { return length == 0; }
  void clear() {
    last = kNone;
    length = 0;
  }
};

// A conditional group being read: where the reading stood at its #if, and at the end of its
// first branch kept (which goes on after #endif).
struct OpenGroup {
  Reading at_open;
  std::optional<Reading> first_end;
};

bool plain_word(const std::string& w) {
  return !w.empty() && (std::isalpha(static_cast<unsigned char>(w[0])) || w[0] == '_' || (w[0] & 0x80));
}

// The prototype of the statement `stmt` (token indices) that a '{' at file level follows, if it
// is a free function's definition.
std::optional<std::string> prototype_of(const std::vector<Token>& tokens, const std::vector<std::size_t>& stmt) {
  auto text = [&](std::size_t j) -> const std::string& { return tokens[stmt[j]].text; };
  const std::size_t n = stmt.size();
  if (n == 0) return std::nullopt;
  for (std::size_t j = 0; j < n; ++j)
    if (is_keyword_start(text(j)) || text(j) == "=" || text(j) == "\"") return std::nullopt;
  // The parameter list: the last ')' before the brace (after it only noexcept/const may stand).
  std::size_t close = n;
  while (close > 0 && text(close - 1) != ")") {
    if (text(close - 1) != "noexcept" && text(close - 1) != "const") break;
    --close;
  }
  if (close == 0 || text(close - 1) != ")") return std::nullopt;
  const std::size_t close_paren = close - 1;
  int level = 0;
  std::size_t open = close_paren + 1;
  bool defaults = false;
  for (std::size_t j = close_paren + 1; j-- > 0;) {
    if (text(j) == ")") ++level;
    if (text(j) == "(" && --level == 0) {
      open = j;
      break;
    }
    if (text(j) == "=" && level == 1) defaults = true;
  }
  if (open > close_paren || open == 0 || defaults) return std::nullopt;
  if (!plain_word(text(open - 1)) || open - 1 == 0) return std::nullopt;  // no return type: a macro call such as ISR(...)
  if (open >= 2 && text(open - 2) == "::") return std::nullopt;          // A::f: a member defined outside its class
  // The tokens joined, spaced as people write them: "static unsigned long *at(const char *s)".
  auto glue_before = [](const std::string& w) { return w == "(" || w == ")" || w == "," || w == "[" || w == "]" || w == "::"; };
  auto glue_after = [](const std::string& w) { return w == "(" || w == "[" || w == "*" || w == "&" || w == "&&" || w == "::"; };
  std::string proto = text(0);
  for (std::size_t j = 1; j <= close_paren; ++j) {
    if (!glue_before(text(j)) && !glue_after(text(j - 1))) proto += ' ';
    proto += text(j);
  }
  return proto + ";";
}

Found find_definitions(std::string_view text) {
  Found f{sketch::tokenize_sketch(text), {}, {}};
  const std::vector<Token>& tokens = f.tokens;
  std::vector<Definition>& found = f.definitions;
  std::size_t here = kNone;  // the branch being read
  std::vector<OpenGroup> groups;
  std::vector<Link> links;
  Reading r;
  auto statement = [&] {  // the token indices of r's statement, in order
    std::vector<std::size_t> out(r.length);
    std::size_t l = r.last;
    for (std::size_t j = r.length; j-- > 0; l = links[l].before) out[j] = links[l].token;
    return out;
  };
  for (std::size_t k = 0; k < tokens.size(); ++k) {
    const Token& tok = tokens[k];
    switch (tok.kind) {
      case TokenKind::OpenGroup:
        groups.push_back({r, std::nullopt});
        f.branches.push_back({here, kNone, k, here == kNone ? 1 : f.branches[here].depth + 1, f.branches.size()});
        here = f.branches.size() - 1;
        continue;
      case TokenKind::OtherBranch:
        if (groups.empty()) continue;  // the lexer gives none outside a group
        if (!groups.back().first_end) groups.back().first_end = r;
        r = groups.back().at_open;
        f.branches.push_back({f.branches[here].parent, here, k, f.branches[here].depth, f.branches[here].group});
        here = f.branches.size() - 1;
        continue;
      case TokenKind::CloseGroup:
        if (groups.empty()) continue;
        here = f.branches[here].parent;
        if (groups.back().first_end) r = *groups.back().first_end;
        // A statement that began inside the group, or grew there, reads differently with other
        // macros: its prototype could name what another branch does not declare.
        if (!r.empty() && (r.level >= groups.size() || r.last != groups.back().at_open.last))
          r.conditional = true;
        groups.pop_back();
        continue;
      case TokenKind::Word:
        break;
    }
    const std::string& t = tok.text;
    if (r.depth > 0) {
      if (t == "{") ++r.depth;
      if (t == "}" && --r.depth == 0) r.clear();
      continue;
    }
    if (r.empty()) {
      r.begins_at = tok.offset;
      r.level = groups.size();
      r.conditional = false;
    }
    if (t == ";" && r.parens == 0) {
      r.clear();
      continue;
    }
    if (t == "}" && r.parens == 0) {  // a stray brace: resynchronise
      r.clear();
      continue;
    }
    if (t == "(" || t == "[") ++r.parens;
    if ((t == ")" || t == "]") && r.parens > 0) --r.parens;
    if (t != "{" || r.parens > 0) {
      links.push_back({k, r.last});
      r.last = links.size() - 1;
      ++r.length;
      continue;
    }
    ++r.depth;
    if (!r.conditional && r.length <= kMaxSignatureTokens)
      if (auto proto = prototype_of(tokens, statement())) found.push_back({std::move(*proto), r.begins_at, here});
    r.clear();
  }
  return f;
}

// The prototypes, each inside the conditions of the branch it is defined in when `wrap`: the
// branches' directives as the source has them, each written once, so that a prototype is
// declared where its function is compiled and nowhere else (its types may exist only there).
std::string prototype_block(const Found& f, bool wrap) {
  std::string out;
  std::vector<std::size_t> open;  // the branches written and not closed, outermost first
  // The directives of a group from the branch after `from` (kNone: its first) to `to`.
  auto directives = [&](std::size_t from, std::size_t to) {
    std::vector<std::size_t> seq;
    for (std::size_t b = to; b != from && b != kNone; b = f.branches[b].before) seq.push_back(b);
    for (auto b = seq.rbegin(); b != seq.rend(); ++b) out += f.tokens[f.branches[*b].token].text + "\n";
  };
  for (const Definition& d : f.definitions) {
    if (wrap) {
      // Up from its branch to one written (or to a branch of a group written, or file level).
      std::vector<std::size_t> chain;
      std::size_t b = d.branch;
      bool sibling = false;
      for (; b != kNone; b = f.branches[b].parent) {
        const std::size_t depth = f.branches[b].depth;
        if (depth <= open.size() && open[depth - 1] == b) break;
        if (depth <= open.size() && f.branches[open[depth - 1]].group == f.branches[b].group) {
          sibling = true;
          break;
        }
        chain.push_back(b);
      }
      const std::size_t keep = b == kNone ? 0 : f.branches[b].depth;
      for (; open.size() > keep; open.pop_back()) out += "#endif\n";
      if (sibling) {
        directives(open.back(), b);
        open.back() = b;
      }
      for (auto c = chain.rbegin(); c != chain.rend(); ++c) {
        directives(kNone, *c);
        open.push_back(*c);
      }
    }
    out += d.prototype + "\n";
  }
  for (; !open.empty(); open.pop_back()) out += "#endif\n";
  return out;
}

// Where prepare_sketch puts the prototypes: before the first function defined outside every
// conditional group, all of them in their groups' conditions (a group on a macro may be left
// out by the compiler, and with it whatever it holds, prototypes included); when every function
// is inside a group (a sketch in an include guard), before the first, unconditionally.
struct Placement {
  std::size_t offset = 0;
  bool wrap = false;
};

Placement place(const Found& f) {
  for (const Definition& d : f.definitions)
    if (d.branch == kNone) return {d.offset, true};
  return {f.definitions.front().offset, false};
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
  for (const Definition& d : find_definitions(text).definitions) out.push_back(d.prototype);
  return out;
}

std::string sketch_prototype_block(std::string_view text) {
  const Found f = find_definitions(text);
  return f.definitions.empty() ? "" : prototype_block(f, place(f).wrap);
}

std::string prepare_sketch(const std::vector<SketchFile>& files) {
  // The files joined, each announced by a #line directive (which the lexer skips), without
  // their byte-order marks (the compiler would read one after #line as stray bytes).
  std::string joined;
  struct Segment {
    std::size_t begin = 0;  // of the file's text in `joined`
    const SketchFile* file = nullptr;
  };
  std::vector<Segment> segments;
  for (const SketchFile& f : files) {
    joined += "#line 1 " + quoted(f.path) + "\n";
    segments.push_back({joined.size(), &f});
    joined += sketch::without_bom(f.text);
    if (joined.empty() || joined.back() != '\n') joined += '\n';
  }
  const Found found = find_definitions(joined);
  std::string out = "#include <Arduino.h>\n";
  if (found.definitions.empty()) return out + joined;
  // Insert at the start of the line when only blanks precede the place.
  const Placement place_at = place(found);
  std::size_t at = place_at.offset;
  const std::size_t line_begin = joined.rfind('\n', at == 0 ? 0 : at - 1);
  const std::size_t bol = line_begin == std::string::npos ? 0 : line_begin + 1;
  bool blank_before = true;
  for (std::size_t i = bol; i < at; ++i)
    if (!std::isspace(static_cast<unsigned char>(joined[i]))) blank_before = false;
  std::string insertion = blank_before ? "" : "\n";
  if (blank_before) at = bol;
  insertion += prototype_block(found, place_at.wrap);
  const Segment* seg = &segments.front();
  for (const Segment& s : segments)
    if (s.begin <= at) seg = &s;
  const std::size_t line = line_of(std::string_view(joined).substr(seg->begin), at - seg->begin);
  insertion += "#line " + std::to_string(line) + " " + quoted(seg->file->path) + "\n";
  return out + joined.substr(0, at) + insertion + joined.substr(at);
}

}  // namespace l6470emu
