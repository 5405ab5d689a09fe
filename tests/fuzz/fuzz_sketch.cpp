// libFuzzer harness of the sketch preprocessor (firmware/sketch_prep.hpp, what l6470emu-ino does
// to .ino files): any text, split into two files at its first NUL byte, gives a translation unit
// that begins with #include <Arduino.h>, holds every file's text unchanged and in order, and
// grows by at most the prototypes (each no longer than three times the text it came from).
#include <string>
#include <string_view>

#include "firmware/sketch_prep.hpp"
#include "fuzz_support.hpp"

using namespace l6470emu;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const std::size_t nul = all.find('\0');
  std::vector<SketchFile> files{{"main.ino", std::string(all.substr(0, nul))}};
  if (nul != std::string_view::npos) files.push_back({"more.ino", std::string(all.substr(nul + 1))});
  const std::string out = prepare_sketch(files);
  FUZZ_CHECK(out.rfind("#include <Arduino.h>\n", 0) == 0, "the unit does not begin with Arduino.h");
  std::size_t at = 0;
  for (const SketchFile& f : files) {
    // Each file's text is there, in order: the prototypes go between two of its pieces at most.
    const std::string head = "#line 1 \"" + f.path + "\"\n";
    const std::size_t begin = out.find(head, at);
    FUZZ_CHECK(begin != std::string::npos, "no #line for %s", f.path.c_str());
    at = begin + head.size();
    const std::string_view rest(out.data() + at, out.size() - at);
    const bool whole = rest.substr(0, f.text.size()) == f.text;
    if (!whole) {
      // Split once by the prototypes: a prefix of the text, the block, then the rest of the text.
      std::size_t k = 0;
      while (k < f.text.size() && k < rest.size() && rest[k] == f.text[k]) ++k;
      const std::size_t line = rest.find("\n#line ", k);
      FUZZ_CHECK(line != std::string_view::npos, "the text of %s is changed, not split", f.path.c_str());
      const std::size_t resume = rest.find('\n', line + 1);
      FUZZ_CHECK(resume != std::string_view::npos, "a #line without its line");
      const std::string_view tail = std::string_view(f.text).substr(k);
      FUZZ_CHECK(rest.substr(resume + 1, tail.size()) == tail, "the text of %s after the prototypes differs",
                 f.path.c_str());
      at += resume + 1 + tail.size();
    } else {
      at += f.text.size();
    }
  }
  FUZZ_CHECK(out.size() <= 4 * size + 200, "the unit is %zu bytes for %zu bytes of sketch", out.size(), size);
  return 0;
}
