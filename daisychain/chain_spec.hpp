// Chain descriptions as text ("3", "3*L6470", "L6470,2*L6480"): the `chain` line of
// a native trace and the --chain option. Only names and counts; quirks are not part of it.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/variant.hpp"
#include "daisychain/chain.hpp"

namespace l6470emu {

/// Parses a chain description, chip 0 first: items separated by commas or spaces, each
/// "VARIANT", "N*VARIANT" or a bare count "N" (N L6470s). Variant names are case-insensitive.
/// Throws std::invalid_argument with a one-line reason (unknown variant, 0 or > 256 chips).
std::vector<const Variant*> parse_chain_spec(std::string_view spec);

/// The shortest description of `variants` ("3*L6470", "L6470,2*L6480").
std::string chain_spec_of(std::span<const Variant* const> variants);

/// The description of a chain's chips.
std::string chain_spec_of(const Chain& chain);

/// A chain of fresh chips of `variants`.
Chain make_chain(std::span<const Variant* const> variants, Quirks quirks = {});

}  // namespace l6470emu
