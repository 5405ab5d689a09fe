// Markdown tables generated from the variant tables the emulator itself uses,
// so the reference pages (docs/reference/tables.md) cannot drift from the model (a test checks them).
#pragma once

#include <string>
#include <string_view>

#include "core/variant.hpp"

namespace l6470emu {

/// Register map of `v`: address, name, bits, SPI bytes, reset value, access class.
std::string register_table_markdown(const Variant& v);

/// STATUS bit layout of `v`, bit 15 first.
std::string status_table_markdown(const Variant& v);

/// The opcodes the decoder accepts and their argument bytes.
std::string command_table_markdown();

/// The commands `v`'s own opcode table decodes (the L6474's: Enable, Disable ...), with their
/// opcodes and argument bytes.
std::string variant_command_table_markdown(const Variant& v);

/// One table of every variant's registers: a row per address, a column per variant (and the
/// powerSTEP01's current-mode reading), each cell "NAME bits/reset/access".
std::string variant_registers_markdown();

/// Every variant's STATUS layout side by side, bit 15 first.
std::string variant_status_markdown();

/// The capabilities that differ (microstepping, ACC = 0xFFF, error bits ...) and every
/// UNCONFIRMED choice, per variant.
std::string variant_differences_markdown();

/// The driver sanitizer's rules (board/check_rules.hpp): name, what it is about, where the
/// datasheet states it.
std::string sanitizer_rules_markdown();

/// The generated block called `name` ("l6470-registers", "l6470-status", "commands", "variant-registers",
/// "variant-status", "variant-differences", "sanitizer-rules", "units", "l6474-registers",
/// "l6474-status", "l6474-commands"), or "" if unknown.
std::string generated_block(std::string_view name);

/// Replaces every `<!-- BEGIN generated:NAME -->` ... `<!-- END generated:NAME -->` block of
/// `text` with the current generated content; returns the new text.
std::string refresh_generated_blocks(std::string_view text);

}  // namespace l6470emu
