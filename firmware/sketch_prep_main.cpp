// l6470emu-ino: turns a sketch's .ino files into one C++ file as the Arduino IDE does
// (firmware/sketch_prep.hpp). Used by l6470emu_add_sketch at build time.
//   l6470emu-ino OUTPUT.cpp MAIN.ino [OTHER.ino ...]
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "firmware/sketch_prep.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: l6470emu-ino OUTPUT.cpp MAIN.ino [OTHER.ino ...]\n";
    return 2;
  }
  std::vector<l6470emu::SketchFile> files;
  for (int i = 2; i < argc; ++i) {
    std::ifstream in(argv[i], std::ios::binary);
    std::ostringstream text;
    if (!in || !(text << in.rdbuf())) {
      // An empty file is a sketch file too; only a file that cannot be read is an error.
      if (!in.is_open() || in.bad()) {
        std::cerr << "l6470emu-ino: " << argv[i] << ": cannot be read\n";
        return 2;
      }
    }
    files.push_back({argv[i], text.str()});
  }
  // The main file first, the others by name (the Arduino IDE's order).
  auto name = [](const std::string& p) { return p.substr(p.find_last_of('/') + 1); };
  std::stable_sort(files.begin() + 1, files.end(),
                   [&](const auto& a, const auto& b) { return name(a.path) < name(b.path); });
  const std::string out = l6470emu::prepare_sketch(files);
  std::ifstream old(argv[1], std::ios::binary);
  std::ostringstream previous;
  if (old) previous << old.rdbuf();
  if (old && previous.str() == out) return 0;  // unchanged: no rebuild
  std::ofstream o(argv[1], std::ios::binary | std::ios::trunc);
  if (!(o << out) || !o.flush()) {
    std::cerr << "l6470emu-ino: " << argv[1] << ": cannot be written\n";
    return 2;
  }
  return 0;
}
