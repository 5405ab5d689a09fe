// What l6470emu-ino does to a sketch (firmware/sketch_prep.hpp): prototypes for the functions
// defined at file level, inserted before the first of them with #line directives that keep
// compiler messages on the sketch's own lines; nothing for what is not a free function.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "firmware/sketch_prep.hpp"

namespace l6470emu::test {
namespace {

using Protos = std::vector<std::string>;

TEST(SketchPrototypes, EveryFunctionDefinedAtFileLevelGetsOneOverloadsIncluded) {
  EXPECT_EQ(sketch_prototypes("void setup() {}\nvoid loop() { helper(3); }\nint helper(int x) { return x; }\n"
                              "void pv(float v) {}\nvoid pv(byte v)\n{\n}\nstatic unsigned long * at(const char *s, int n[]) "
                              "{ return 0; }\n"),
            (Protos{"void setup();", "void loop();", "int helper(int x);", "void pv(float v);", "void pv(byte v);",
                    "static unsigned long *at(const char *s, int n[]);"}));
}

TEST(SketchPrototypes, ClassesNamespacesMembersTemplatesOperatorsMacrosAndDefaultsGetNone) {
  const std::string text = R"(
struct Motor { void step() { n++; } int n; };
class Axis { public: Axis(int p) : pin(p) {} int pin; };
namespace util { int twice(int x) { return 2 * x; } }
extern "C" { void c_function(void) {} }
void Axis::home() { }
template <typename T> T clamp(T v) { return v; }
bool operator==(const Motor& a, const Motor& b) { return a.n == b.n; }
ISR(TIMER1_COMPA_vect) { }
int defaults(int a, int b = 3) { return a + b; }
int table[] = {1, 2, 3};
auto lambda = []() { return 1; };
enum Dir { FWD, REV };
void kept(Dir d) { }
)";
  EXPECT_EQ(sketch_prototypes(text), (Protos{"void kept(Dir d);"}));
}

TEST(SketchPrototypes, BracesInCommentsStringsCharactersRawStringsAndDirectivesDoNotCount) {
  const std::string text = "// void commented() {\n/* void block() { */\nconst char* s = \"void in_string() {\";\n"
                           "char c = '{';\nconst char* r = R\"x(void raw() { )x\";\n#define BODY() { \\\n  return; }\n"
                           "#if 0\n#endif\nvoid real(const char* t) { if (t[0] == '}') { } }\nvoid after() {}\n";
  EXPECT_EQ(sketch_prototypes(text), (Protos{"void real(const char *t);", "void after();"}));
}

TEST(SketchPreparation, ArduinoHFirstPrototypesBeforeTheFirstDefinitionAndLinesKept) {
  const std::string main = "#include <SPI.h>\nconst int kCs = 10;\n\nvoid setup() { go(); }\nvoid loop() {}\n";
  const std::string other = "// helpers\nvoid go() {\n}\n";
  const std::string out = prepare_sketch({{"/s/main.ino", main}, {"/s/b.ino", other}});
  EXPECT_EQ(out,
            "#include <Arduino.h>\n"
            "#line 1 \"/s/main.ino\"\n"
            "#include <SPI.h>\nconst int kCs = 10;\n\n"
            "void setup();\nvoid loop();\nvoid go();\n"
            "#line 4 \"/s/main.ino\"\n"
            "void setup() { go(); }\nvoid loop() {}\n"
            "#line 1 \"/s/b.ino\"\n"
            "// helpers\nvoid go() {\n}\n");
}

TEST(SketchPreparation, AFileWithoutFunctionsAndOddNamesStayWholeAndQuoted) {
  EXPECT_EQ(prepare_sketch({{"a\"b.ino", "int x = 1;"}}), "#include <Arduino.h>\n#line 1 \"a\\\"b.ino\"\nint x = 1;\n");
  // A definition after other text on its line: the prototypes start a line of their own.
  EXPECT_EQ(prepare_sketch({{"m.ino", "int x; void f() {}\n"}}),
            "#include <Arduino.h>\n#line 1 \"m.ino\"\nint x; \nvoid f();\n#line 1 \"m.ino\"\nvoid f() {}\n");
}

TEST(SketchPreparation, UnterminatedTextAndStrayBracesEndWithoutACrash) {
  for (const char* text : {"void f() {", "}}}} void g() {}", "\"unterminated", "/* open", "R\"x(never", "#define X \\",
                           "void h(", ")))) {", "'", "int a[ = {"})
    EXPECT_NO_THROW(prepare_sketch({{"x.ino", text}})) << text;
  EXPECT_EQ(sketch_prototypes("}}}} void g() {}"), (Protos{"void g();"}));
}

}  // namespace
}  // namespace l6470emu::test
