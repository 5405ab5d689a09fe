#include "linux/serve/control_words.hpp"

namespace l6470emu {

std::string join_control_words(const std::vector<std::string>& words) {
  std::string line;
  for (const std::string& w : words) {
    if (!line.empty()) line += ' ';
    if (!w.empty() && w.find_first_of(" \t\"\\") == std::string::npos) {
      line += w;
      continue;
    }
    line += '"';
    for (const char c : w) {
      if (c == '"' || c == '\\') line += '\\';
      line += c;
    }
    line += '"';
  }
  return line;
}

std::vector<std::string> split_control_words(std::string_view line) {
  std::vector<std::string> words;
  std::size_t i = 0;
  while (true) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i >= line.size()) return words;
    std::string w;
    bool quoted = false;
    for (; i < line.size(); ++i) {
      const char c = line[i];
      if (quoted) {
        if (c == '\\' && i + 1 < line.size() && (line[i + 1] == '"' || line[i + 1] == '\\')) {
          w += line[++i];
        } else if (c == '"') {
          quoted = false;
        } else {
          w += c;
        }
      } else if (c == ' ' || c == '\t') {
        break;
      } else if (c == '"') {
        quoted = true;
      } else {
        w += c;
      }
    }
    words.push_back(std::move(w));
  }
}

}  // namespace l6470emu
