// The generated tables of the documents (registers, STATUS, commands, variants, units in
// docs/reference/tables.md; the sanitizer's rules in docs/linux.md) are the model's own tables.
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
