// The report page: one self-contained HTML file (tools/report_data.hpp's data as JSON, the
// charting library dygraphs and the page's own script and styles, all inline; a content
// security policy that lets it load nothing), which any browser opens from a disk or a CI's
// artifact store.
#pragma once

#include <iosfwd>
#include <string>

#include "tools/report_data.hpp"

namespace l6470emu {

/// Whether this program carries the charting library (it is taken from Debian's
/// libjs-dygraphs when the program is built); without it no page can be written.
bool report_page_available();

/// Writes the page of `data` to `out`.
void write_report_page(const ReportData& data, std::ostream& out);

}  // namespace l6470emu
