// Text for XML reports (run's and campaign's JUnit files): any bytes made into well-formed XML
// character data or attribute values.
#pragma once

#include <string>
#include <string_view>

namespace l6470emu {

/// `s` with &, <, >, " and ' escaped, control characters other than newline and tab made spaces
/// (XML 1.0 has no way to carry them) and every byte that is not part of valid UTF-8 replaced
/// by U+FFFD.
std::string xml_text(std::string_view s);

}  // namespace l6470emu
