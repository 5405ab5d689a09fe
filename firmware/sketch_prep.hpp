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
/// follow in the order given; the caller sorts them by name as the IDE does). A UTF-8
/// byte-order mark at the start of a file is dropped; the rest of each file's text is kept as it
/// is. #line directives keep compiler messages on the sketch's own files and lines. Prototypes
/// (the definition's text up to its closing parenthesis, comments left out and lines joined at
/// backslash-newline) go just before the first function defined at file level outside any
/// conditional group; functions inside classes, namespaces or extern "C" blocks, member
/// functions defined outside their class (A::f), operators, templates and functions with
/// default arguments get none. Conditional groups the compiler skips whatever the macros
/// (`#if 0`, the `#else` of `#if 1`) count for nothing. A function inside another group
/// (`#ifdef X`) gets its prototype inside the same conditions, written again around it; a
/// function whose signature is only partly inside such a group gets none. When every function
/// is inside a group (an include guard), the prototypes go before the first, unconditionally.
std::string prepare_sketch(const std::vector<SketchFile>& files);

/// The prototypes prepare_sketch makes for `text`, in order (for tests and the fuzz harness).
std::vector<std::string> sketch_prototypes(std::string_view text);

/// The lines prepare_sketch inserts for `text` before its #line directive: the prototypes with
/// the conditions around them; empty without prototypes (for the fuzz harness).
std::string sketch_prototype_block(std::string_view text);

}  // namespace l6470emu
