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

// Issue 35: three sketches the Arduino IDE builds that broke the preprocessor.
TEST(SketchPrototypes, ASignatureSplitByBackslashNewlineIsJoinedAsTheCompilerJoinsIt) {
  EXPECT_EQ(sketch_prototypes("long add_three(long a, \\\n               long b, \\\r\n long c) { return a + b + c; }\n"
                              "void lo\\\nop() {}\nvoid spaced(int a, \\  \n int b) {}\n"),
            (Protos{"long add_three(long a, long b, long c);", "void loop();", "void spaced(int a, int b);"}));
}

TEST(SketchPreparation, ASplitSignatureKeepsItsTextAndTheLineOfWhatFollows) {
  const std::string main = "int total = 1 + \\\n  2;\nvoid setup() { add(1, \\\n 2); }\nint add(int a, \\\n        int b) { return a + b; }\n";
  EXPECT_EQ(prepare_sketch({{"m.ino", main}}),
            "#include <Arduino.h>\n#line 1 \"m.ino\"\nint total = 1 + \\\n  2;\n"
            "void setup();\nint add(int a, int b);\n#line 3 \"m.ino\"\n"
            "void setup() { add(1, \\\n 2); }\nint add(int a, \\\n        int b) { return a + b; }\n");
}

TEST(SketchPrototypes, AnIfZeroGroupWithAnUnbalancedBraceCountsForNothing) {
  EXPECT_EQ(sketch_prototypes("#if 0\nvoid old_version() {\n  if (x) {\n#endif\nvoid setup() { twice(2); }\n"
                              "int twice(int x) { return 2 * x; }\n"),
            (Protos{"void setup();", "int twice(int x);"}));
}

TEST(SketchPreparation, PrototypesAndTheirLineDirectiveGoAfterAnIfZeroGroupNeverInsideIt) {
  const std::string main = "#include <SPI.h>\n#if 0\nvoid old_version() {\n#endif\n\nvoid setup() { twice(2); }\n"
                           "int twice(int x) { return 2 * x; }\n";
  EXPECT_EQ(prepare_sketch({{"m.ino", main}}),
            "#include <Arduino.h>\n#line 1 \"m.ino\"\n#include <SPI.h>\n#if 0\nvoid old_version() {\n#endif\n\n"
            "void setup();\nint twice(int x);\n#line 6 \"m.ino\"\n"
            "void setup() { twice(2); }\nint twice(int x) { return 2 * x; }\n");
}

TEST(SketchPreparation, AByteOrderMarkAtTheStartOfAFileIsDropped) {
  const std::string bom = "\xEF\xBB\xBF";
  EXPECT_EQ(prepare_sketch({{"m.ino", bom + "void setup() { go(); }\n"}, {"b.ino", bom + "// b\nvoid go() {}\n"}}),
            "#include <Arduino.h>\n#line 1 \"m.ino\"\nvoid setup();\nvoid go();\n#line 1 \"m.ino\"\n"
            "void setup() { go(); }\n#line 1 \"b.ino\"\n// b\nvoid go() {}\n");
  EXPECT_EQ(sketch_prototypes(bom + "int f() { return 1; }\n"), (Protos{"int f();"}));
  // Only at the start: elsewhere the bytes are the sketch's own (the compiler's to refuse).
  EXPECT_EQ(prepare_sketch({{"m.ino", "int x;" + bom + "\n"}}), "#include <Arduino.h>\n#line 1 \"m.ino\"\nint x;" + bom + "\n");
}

TEST(SketchPrototypes, ConstantConditionsDecideWhichBranchesCount) {
  const std::string text = "#if 1\nvoid a() {}\n#else\nvoid b() {\n#endif\n"
                           "#if false\nvoid c() {}\n#elif 0x0\nvoid d() {\n#elif (1)\nvoid e() {}\n#else\nvoid f() {\n#endif\n"
                           "#if 0\n#ifdef X\nvoid g() {}\n#else\nvoid h() {}\n#endif\n#else\nvoid i() {}\n#endif\n"
                           "#if 0 // off\n{\n#endif\n#if /* off */ 0\n{\n#endif\n#  if 0UL\n{\n#  endif\nvoid j() {}\n";
  EXPECT_EQ(sketch_prototypes(text), (Protos{"void a();", "void e();", "void i();", "void j();"}));
}

TEST(SketchPrototypes, EachBranchOfAGroupOnAMacroCountsFromTheDepthTheGroupBeganAt) {
  // Two openings of one body: every prototype after it used to be lost.
  EXPECT_EQ(sketch_prototypes("#ifdef FAST\nvoid step(int n) {\n#elif defined(SLOW)\nvoid step(long n) {\n#else\n"
                              "void step(short n) {\n#endif\n  go(n);\n}\nvoid after() {}\n"),
            (Protos{"void step(int n);", "void step(long n);", "void step(short n);", "void after();"}));
  // A function in such a group gets its prototype; one whose signature is only partly inside
  // one gets none (with other macros it would read otherwise).
  EXPECT_EQ(sketch_prototypes("#ifdef DEBUG\nvoid dump() {}\n#endif\n#ifdef WIDE\nlong\n#else\nint\n#endif\nvalue() {}\n"
                              "void f(\n#ifdef WIDE\nlong x\n#else\nint x\n#endif\n) {}\n#ifdef ESP32\n#endif\nvoid g() {}\n"),
            (Protos{"void dump();", "void g();"}));
}

// The same failure on a group the preprocessor cannot decide: an ISR for one platform above the
// functions took the prototypes and the #line into its #ifdef, lost on every other platform.
TEST(SketchPreparation, AFunctionInAGroupOnAMacroIsDeclaredInsideTheSameConditionsAfterIt) {
  const std::string main = "#ifdef ESP32\nvoid IRAM_ATTR on_flag() {}\n#endif\nvoid setup() { helper(); }\n"
                           "void helper() {}\n";
  EXPECT_EQ(prepare_sketch({{"m.ino", main}}),
            "#include <Arduino.h>\n#line 1 \"m.ino\"\n#ifdef ESP32\nvoid IRAM_ATTR on_flag() {}\n#endif\n"
            "#ifdef ESP32\nvoid IRAM_ATTR on_flag();\n#endif\nvoid setup();\nvoid helper();\n#line 4 \"m.ino\"\n"
            "void setup() { helper(); }\nvoid helper() {}\n");
}

TEST(SketchPreparation, NestedGroupsAndTheirBranchesAreWrittenOnceEachAsTheSourceHasThem) {
  const std::string text = "void setup() {}\n#ifdef A\nvoid a() {}\n#ifdef B // b\nvoid b() {}\n#endif\nvoid a2() {}\n"
                           "#elif defined(C)\nvoid c() {}\n#else\nvoid d() {}\n#endif\n"
                           "#if 0\nvoid z() {}\n#elif X > 1\nvoid x() {}\n#else\n#endif\n#ifdef A\nvoid a3() {}\n#endif\n";
  EXPECT_EQ(sketch_prototype_block(text),
            "void setup();\n#ifdef A\nvoid a();\n#ifdef B\nvoid b();\n#endif\nvoid a2();\n#elif defined(C)\nvoid c();\n"
            "#else\nvoid d();\n#endif\n#if X > 1\nvoid x();\n#endif\n#ifdef A\nvoid a3();\n#endif\n");
}

TEST(SketchPreparation, WhenEveryFunctionIsInAGroupThePrototypesGoBeforeTheFirstUnconditionally) {
  // A sketch in an include guard: the guard's condition, written again after its #define, would
  // be false.
  EXPECT_EQ(prepare_sketch({{"m.ino", "#ifndef M_INO\n#define M_INO\nvoid setup() { go(); }\nvoid go() {}\n#endif\n"}}),
            "#include <Arduino.h>\n#line 1 \"m.ino\"\n#ifndef M_INO\n#define M_INO\nvoid setup();\nvoid go();\n"
            "#line 3 \"m.ino\"\nvoid setup() { go(); }\nvoid go() {}\n#endif\n");
}

}  // namespace
}  // namespace l6470emu::test
