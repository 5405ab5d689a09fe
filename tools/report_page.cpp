// write_report_page: the HTML shell around the data and the embedded scripts (report_assets.cpp,
// generated at build time by cmake/embed_assets.cmake from tools/report/ and libjs-dygraphs).
#include "tools/report_page.hpp"

#include <cstddef>
#include <ostream>
#include <string_view>

#include "tools/xml_text.hpp"

namespace l6470emu {

extern const unsigned char kReportScript[];
extern const std::size_t kReportScript_size;
extern const unsigned char kReportStyle[];
extern const std::size_t kReportStyle_size;
extern const unsigned char kDygraphScript[];
extern const std::size_t kDygraphScript_size;
extern const unsigned char kDygraphStyle[];
extern const std::size_t kDygraphStyle_size;

namespace {

std::string_view asset(const unsigned char* data, std::size_t size) { return {reinterpret_cast<const char*>(data), size}; }

/// JSON inside a <script> element: '<' escaped, so no "</script>" or "<!--" can end it early.
void put_json(std::ostream& out, std::string_view json) {
  std::size_t from = 0;
  for (std::size_t i = 0; i < json.size(); ++i)
    if (json[i] == '<') {
      out << json.substr(from, i - from) << "\\u003c";
      from = i + 1;
    }
  out << json.substr(from);
}

}  // namespace

bool report_page_available() { return kDygraphScript_size > 0; }

void write_report_page(const ReportData& data, std::ostream& out) {
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
         // Nothing outside the file: no fetch, no image, no font, no frame.
         "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; script-src 'unsafe-inline'; "
         "style-src 'unsafe-inline'; img-src data:\">\n"
         "<meta name=\"generator\" content=\"l6470emu report\">\n"
      << "<title>l6470emu report: " << xml_text(data.title) << "</title>\n<style>\n"
      << asset(kDygraphStyle, kDygraphStyle_size) << "\n"
      << asset(kReportStyle, kReportStyle_size) << "</style>\n</head>\n<body>\n"
      << "<noscript><p>This report is drawn by the JavaScript it carries: open it in a browser with "
         "JavaScript on.</p></noscript>\n<div id=\"app\"></div>\n"
      << "<script type=\"application/json\" id=\"report-data\">";
  put_json(out, report_json(data));
  out << "</script>\n<script>\n" << asset(kDygraphScript, kDygraphScript_size) << "\n</script>\n<script>\n"
      << asset(kReportScript, kReportScript_size) << "\n</script>\n</body>\n</html>\n";
}

}  // namespace l6470emu
