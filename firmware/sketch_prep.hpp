// What the Arduino IDE does to a sketch's .ino files before compiling them as C++: one
// translation unit beginning with #include <Arduino.h>, the main file first and the others by
// name, and a prototype for each function defined at file level, so that a function may be
// called above its definition. Text in, text out; no compiler, no files.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace l6470emu {

/// One .ino file: the name #line directives give it, and its text.
struct SketchFile {
  std::string path;
  std::string text;
};

/// The C++ translation unit of a sketch whose files are `files`, the main one first (the others
/// follow in the order given; the caller sorts them by name as the IDE does). #line directives
/// keep compiler messages on the sketch's own files and lines. Prototypes (the definition's
/// text up to its closing parenthesis, comments left out) go just before the first function
/// defined at file level; functions inside classes, namespaces or extern "C" blocks, member
/// functions defined outside their class (A::f), operators, templates and functions with
/// default arguments get none.
std::string prepare_sketch(const std::vector<SketchFile>& files);

/// The prototypes prepare_sketch makes for `text`, in order (for tests).
std::vector<std::string> sketch_prototypes(std::string_view text);

}  // namespace l6470emu
