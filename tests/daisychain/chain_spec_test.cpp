// Chain descriptions (daisychain/chain_spec.hpp): "3", "3*L6470", "L6470,2*L6480".
#include <gtest/gtest.h>

#include "daisychain/chain_spec.hpp"

namespace l6470emu {
namespace {

TEST(ChainSpec, ReadsCountsVariantsAndLists) {
  EXPECT_EQ(parse_chain_spec("3"), (std::vector<const Variant*>(3, &l6470())));
  EXPECT_EQ(parse_chain_spec("2*l6480"), (std::vector<const Variant*>(2, &l6480())));
  EXPECT_EQ(parse_chain_spec("L6470, 2xpowerSTEP01"),
            (std::vector<const Variant*>{&l6470(), &powerstep01(), &powerstep01()}));
}

TEST(ChainSpec, PrintsTheShortestDescription) {
  const std::vector<const Variant*> v{&l6470(), &l6470(), &l6480(), &l6470()};
  EXPECT_EQ(chain_spec_of(v), "2*L6470,L6480,L6470");
  EXPECT_EQ(parse_chain_spec(chain_spec_of(v)), v);
  EXPECT_EQ(chain_spec_of(Chain(4)), "4*L6470");
}

TEST(ChainSpec, RejectsWhatIsNoChainInOneLine) {
  auto error_of = [](const char* s) {
    try {
      parse_chain_spec(s);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(error_of("L6499"),
            "unknown chip variant \"L6499\" (did you mean L6470, L6472, L6480, L6482 or L6474? known: L6470, L6472, "
            "L6480, L6482, powerSTEP01, L6474)");
  EXPECT_EQ(error_of("0"), "chain item \"0\" has no chips");
  EXPECT_EQ(error_of("300"), "a chain has at most 256 chips");
  EXPECT_EQ(error_of(""), "empty chain description (e.g. 3, 3*L6470 or L6470,L6480)");
  EXPECT_EQ(error_of("3-L6470"), "chain item \"3-L6470\" is not N, VARIANT or N*VARIANT");
}

}  // namespace
}  // namespace l6470emu
