// The generated tables of the documents (registers, STATUS, commands, variants, units in
// docs/reference/tables.md; the sanitizer's rules in docs/linux.md; the L6474's register map,
// STATUS and commands in docs/l6474.md) are the model's own tables.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "tools/tables.hpp"

namespace l6470emu {
namespace {

std::string read_tables_page() {
  std::ifstream in(std::string(L6470EMU_SOURCE_DIR) + "/docs/reference/tables.md");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Docs, TheTablesPagesTablesMatchTheModel) {
  const std::string text = read_tables_page();
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(refresh_generated_blocks(text), text)
      << "docs/reference/tables.md is stale: run build/l6470emu tables --update-readme docs/reference/tables.md";
}

TEST(Docs, TheLinuxPagesSanitizerRulesMatchTheModel) {
  std::ifstream in(std::string(L6470EMU_SOURCE_DIR) + "/docs/linux.md");
  std::stringstream s;
  s << in.rdbuf();
  const std::string text = s.str();
  ASSERT_NE(text.find("<!-- BEGIN generated:sanitizer-rules -->"), std::string::npos);
  EXPECT_EQ(refresh_generated_blocks(text), text)
      << "docs/linux.md's rules table is stale: run build/l6470emu tables --update-readme docs/linux.md";
}

TEST(Docs, TheL6474PagesTablesMatchTheModel) {
  std::ifstream in(std::string(L6470EMU_SOURCE_DIR) + "/docs/l6474.md");
  std::stringstream s;
  s << in.rdbuf();
  const std::string text = s.str();
  for (const char* name : {"l6474-registers", "l6474-status", "l6474-commands"})
    EXPECT_NE(text.find(std::string("<!-- BEGIN generated:") + name + " -->"), std::string::npos) << name;
  EXPECT_EQ(refresh_generated_blocks(text), text)
      << "docs/l6474.md is stale: run build/l6470emu tables --update-readme docs/l6474.md";
}

TEST(VariantCommandTableMarkdown, ListsTheL6474sSixCommandsAndNothingThatMoves) {
  const std::string t = variant_command_table_markdown(l6474());
  for (const char* row : {"| NOP | 0x00 | 0 |", "| SetParam | 0x01–0x03, 0x09, 0x0E–0x10, 0x12–0x13, 0x16–0x19 |",
                          "| GetParam | 0x21–0x23, 0x29, 0x2E–0x30, 0x32–0x33, 0x36–0x39 |", "| Disable | 0xA8 | 0 |",
                          "| Enable | 0xB8 | 0 |", "| GetStatus | 0xD0 | 0 (answer: 2) |"})
    EXPECT_NE(t.find(row), std::string::npos) << row << "\n" << t;
  for (const char* absent : {"Move", "Run", "GoTo", "HardStop", "ResetDevice"})
    EXPECT_EQ(t.find(absent), std::string::npos) << absent;
}

TEST(Docs, TheTablesPageHasEveryGeneratedBlock) {
  const std::string text = read_tables_page();
  for (const char* name : {"l6470-registers", "l6470-status", "commands", "variant-registers", "variant-status",
                           "variant-differences", "units"})
    EXPECT_NE(text.find(std::string("<!-- BEGIN generated:") + name + " -->"), std::string::npos) << name;
}

TEST(RegisterTableMarkdown, ListsEveryL6470RegisterAndTheReservedAddresses) {
  const std::string t = register_table_markdown(l6470());
  for (const auto& r : l6470().registers) EXPECT_NE(t.find(std::string(r.name)), std::string::npos) << r.name;
  EXPECT_NE(t.find("| 0x1A | (none)"), std::string::npos);
  EXPECT_NE(t.find("| 0x18 | CONFIG | 16 | 2 | 0x2E88 | WH |"), std::string::npos);
}

TEST(StatusTableMarkdown, PutsSckModOnBit15AndHizOnBit0) {
  const std::string t = status_table_markdown(l6470());
  EXPECT_NE(t.find("| 15 | SCK_MOD"), std::string::npos);
  EXPECT_NE(t.find("| 0 | HiZ |"), std::string::npos);
}

}  // namespace
}  // namespace l6470emu
