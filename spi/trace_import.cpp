// Format names, recognising a format from the start of a file, and the dispatcher.
#include "spi/trace_import.hpp"

#include "spi/import_source.hpp"
#include "spi/trace_native.hpp"

namespace l6470emu {

std::string_view to_string(TraceFormat f) {
  switch (f) {
    case TraceFormat::unknown: return "unknown";
    case TraceFormat::native: return "native";
    case TraceFormat::saleae: return "saleae";
    case TraceFormat::umockdev: return "umockdev";
    case TraceFormat::ftrace: return "ftrace";
    case TraceFormat::sigrok: return "sigrok";
    case TraceFormat::vcd: return "vcd";
  }
  return "unknown";
}

TraceFormat trace_format_named(std::string_view name) {
  for (TraceFormat f : {TraceFormat::native, TraceFormat::saleae, TraceFormat::umockdev, TraceFormat::ftrace,
                        TraceFormat::sigrok, TraceFormat::vcd})
    if (name == to_string(f)) return f;
  return TraceFormat::unknown;
}

namespace {

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

}  // namespace

TraceFormat detect_trace_format(std::string_view head, std::string_view file_name) {
  if (ends_with(file_name, ".sr")) return TraceFormat::vcd;  // sigrok session: decoded by sigrok-cli too
  if (head.substr(0, 3) == "\xEF\xBB\xBF") head.remove_prefix(3);  // UTF-8 byte order mark
  if (head.rfind("l6470emu-trace", 0) == 0) return TraceFormat::native;
  std::size_t i = 0;
  while (i < head.size() && (head[i] == ' ' || head[i] == '\t' || head[i] == '\r' || head[i] == '\n')) ++i;
  const std::string_view body = head.substr(i);
  if (!body.empty() && (body[0] == '{' || body[0] == '[') &&
      (body.find("traceEvents") != std::string_view::npos || body.find("\"ph\"") != std::string_view::npos))
    return TraceFormat::sigrok;
  if (!body.empty() && body[0] == '$') return TraceFormat::vcd;
  if (ends_with(file_name, ".vcd")) return TraceFormat::vcd;
  if (body.rfind("@DEV", 0) == 0) return TraceFormat::umockdev;
  if (head.find("spi_transfer_start:") != std::string_view::npos ||
      head.find("spi_transfer_stop:") != std::string_view::npos ||
      head.find("spi_set_cs:") != std::string_view::npos || head.find("spi_message_start:") != std::string_view::npos)
    return TraceFormat::ftrace;
  const std::string_view first_line = body.substr(0, body.find('\n'));
  if (first_line.find(',') != std::string_view::npos &&
      (first_line.find("start_time") != std::string_view::npos || first_line.find("Time [s]") != std::string_view::npos))
    return TraceFormat::saleae;
  if (body.size() >= 3 && (body[0] == 'T' || body[0] == 'C') && (body[1] == 'W' || body[1] == 'R') && body[2] == ' ')
    return TraceFormat::umockdev;
  if (body.rfind("# tracer:", 0) == 0) return TraceFormat::ftrace;
  return TraceFormat::unknown;
}

namespace {

Trace import_from(detail::ImportSource& source, TraceFormat format, const ImportOptions& options) {
  switch (format) {
    case TraceFormat::saleae: return detail::import_saleae(source, options);
    case TraceFormat::umockdev: return detail::import_umockdev(source, options);
    case TraceFormat::ftrace: return detail::import_ftrace(source, options);
    case TraceFormat::sigrok: return detail::import_sigrok(source, options);
    case TraceFormat::vcd:
      throw TraceError(source.name(), 0, "a logic capture (VCD or .sr) must be decoded by sigrok-cli first");
    case TraceFormat::native:
    case TraceFormat::unknown: break;
  }
  throw TraceError(source.name(), 0,
                   "unknown trace format (native, Saleae CSV, umockdev .ioctl, ftrace text, sigrok JSON trace or VCD)");
}

Trace read_all(NativeTraceReader& reader) {
  Trace t;
  t.header = reader.header();
  TraceEvent e;
  while (reader.next(e)) t.write(e);
  return t;
}

}  // namespace

Trace import_saleae_csv(std::string_view text, const std::string& name, const ImportOptions& options) {
  detail::ImportSource source(text, name);
  return detail::import_saleae(source, options);
}

Trace import_umockdev_ioctl(std::string_view text, const std::string& name, const ImportOptions& options) {
  detail::ImportSource source(text, name);
  return detail::import_umockdev(source, options);
}

Trace import_ftrace(std::string_view text, const std::string& name, const ImportOptions& options) {
  detail::ImportSource source(text, name);
  return detail::import_ftrace(source, options);
}

Trace import_sigrok_json(std::string_view text, const std::string& name, const ImportOptions& options) {
  detail::ImportSource source(text, name);
  return detail::import_sigrok(source, options);
}

Trace import_trace(std::string_view text, const std::string& name, TraceFormat format, const ImportOptions& options) {
  if (format == TraceFormat::native) return read_native_trace(text, name, options.max_frames);
  detail::ImportSource source(text, name);
  return import_from(source, format, options);
}

Trace import_trace_file(const std::string& path, TraceFormat format, const ImportOptions& options) {
  if (format == TraceFormat::native) {
    NativeTraceReader reader(path, options.max_frames);
    return read_all(reader);
  }
  if (format == TraceFormat::vcd || format == TraceFormat::unknown) {
    detail::ImportSource none(std::string_view{}, path);
    return import_from(none, format, options);
  }
  detail::ImportSource source(path);
  source.on_progress(options.progress);
  return import_from(source, format, options);
}

}  // namespace l6470emu
