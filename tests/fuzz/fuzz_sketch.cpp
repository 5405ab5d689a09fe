// libFuzzer harness of the sketch preprocessor (firmware/sketch_prep.hpp, what l6470emu-ino does
// to .ino files): any text, split into two files at its first NUL byte, gives a translation unit
// that begins with #include <Arduino.h>, holds every file's text (without a leading byte-order
// mark) unchanged and in order, and grows by at most the prototypes and the conditions written
// around them (linearly). Its lexer's tokens stay in order inside the text, and its conditional
// groups' marks nest.
#include <string>
#include <string_view>

#include "firmware/sketch_lexer_internal.hpp"
#include "firmware/sketch_prep.hpp"
#include "fuzz_support.hpp"

using namespace l6470emu;

namespace {

void check_tokens(std::string_view text) {
  std::size_t last = 0;
  int open = 0;
  for (const sketch::Token& t : sketch::tokenize_sketch(text)) {
    FUZZ_CHECK(t.offset >= last && t.offset < text.size(), "a token at %zu after %zu in %zu bytes", t.offset, last,
               text.size());
    last = t.offset;
    switch (t.kind) {
      case sketch::TokenKind::Word:
        FUZZ_CHECK(!t.text.empty() && t.text.size() <= text.size() - t.offset, "a token of %zu bytes at %zu",
                   t.text.size(), t.offset);
        break;
      case sketch::TokenKind::OpenGroup:
        ++open;
        break;
      case sketch::TokenKind::OtherBranch:
        FUZZ_CHECK(open > 0, "a branch mark outside a group at %zu", t.offset);
        break;
      case sketch::TokenKind::CloseGroup:
        FUZZ_CHECK(open-- > 0, "a group closed that was not open at %zu", t.offset);
        break;
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  check_tokens(all);
  const std::size_t nul = all.find('\0');
  std::vector<SketchFile> files{{"main.ino", std::string(all.substr(0, nul))}};
  if (nul != std::string_view::npos) files.push_back({"more.ino", std::string(all.substr(nul + 1))});
  const std::string out = prepare_sketch(files);
  FUZZ_CHECK(out.rfind("#include <Arduino.h>\n", 0) == 0, "the unit does not begin with Arduino.h");
  // The prototypes, as the preprocessor finds them in the files joined (its #line lines are
  // directives, which the tokenizer skips), make the one block it may insert.
  std::string joined;
  for (const SketchFile& f : files) {
    joined += "#line 1 \"" + f.path + "\"\n" + std::string(sketch::without_bom(f.text));
    if (joined.back() != '\n') joined += '\n';  // as prepare_sketch ends a file: one newline, none doubled
  }
  std::string block = sketch_prototype_block(joined);
  std::size_t prototypes = 0;
  for (const std::string& p : sketch_prototypes(joined)) {
    FUZZ_CHECK(block.find(p + "\n") != std::string::npos, "the prototype %s is not in the block", p.c_str());
    ++prototypes;
  }
  FUZZ_CHECK((prototypes == 0) == block.empty(), "a block of %zu bytes for %zu prototypes", block.size(), prototypes);
  bool inserted = block.empty();  // no prototypes: nothing is inserted anywhere
  block += "#line ";
  std::size_t at = 0;
  for (const SketchFile& f : files) {
    const std::string head = "#line 1 \"" + f.path + "\"\n";
    const std::size_t begin = out.find(head, at);
    FUZZ_CHECK(begin != std::string::npos, "no #line for %s", f.path.c_str());
    at = begin + head.size();
    const std::string_view rest(out.data() + at, out.size() - at);
    const std::string_view text = sketch::without_bom(f.text);
    if (rest.substr(0, text.size()) == text && (inserted || rest.substr(text.size(), block.size()) != block)) {
      at += text.size();
      continue;
    }
    // Split once by the block: a prefix of the text (perhaps followed by a newline of the
    // block's own), the block and its #line line, then the rest of the text.
    bool found = false;
    for (std::size_t pos = rest.find(block); pos != std::string_view::npos && !found; pos = rest.find(block, pos + 1)) {
      const std::size_t line_end = rest.find('\n', pos + block.size());
      if (line_end == std::string_view::npos) break;
      for (const std::size_t split : {pos, pos == 0 ? pos : pos - 1}) {
        if (split > text.size() || rest.substr(0, split) != text.substr(0, split)) continue;
        if (split != pos && rest[split] != '\n') continue;
        const std::string_view tail = text.substr(split);
        if (rest.substr(line_end + 1, tail.size()) != tail) continue;
        found = true;
        at += line_end + 1 + tail.size();
        break;
      }
    }
    FUZZ_CHECK(found && !inserted, "the text of %s is changed, not split once by the prototypes", f.path.c_str());
    inserted = true;
  }
  FUZZ_CHECK(out.size() <= 4 * size + 200, "the unit is %zu bytes for %zu bytes of sketch", out.size(), size);
  return 0;
}
