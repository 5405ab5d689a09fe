// Trace files on disk, plain or gzip-compressed: a reader that recognises gzip by its magic
// bytes (1F 8B) and a writer that compresses when the file name ends in ".gz". Bytes only:
// what the bytes mean is the formats' business (trace_native.hpp, trace_import.hpp).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace l6470emu {

/// Whether `head` (the first bytes of a file) starts with the gzip magic bytes 1F 8B.
bool starts_with_gzip_magic(std::string_view head);
/// Whether a file called `path` is written gzip-compressed (its name ends in ".gz").
bool gzip_file_name(std::string_view path);
/// `path` without a trailing ".gz" (the name that says what is inside: "run.trace.gz" -> "run.trace").
std::string_view without_gz(std::string_view path);

/// Reads a file's bytes, gunzipped when the file starts with the gzip magic. Errors are
/// TraceError naming the file; a read error or damaged gzip data also names the line it
/// falls in (1-based, of the uncompressed text: every line before it was handed out) and
/// how many bytes came before it.
class TraceFileReader {
 public:
  /// Opens `path`. Throws TraceError ("run.trace: cannot open: No such file or directory").
  explicit TraceFileReader(const std::string& path);
  ~TraceFileReader();
  TraceFileReader(const TraceFileReader&) = delete;
  TraceFileReader& operator=(const TraceFileReader&) = delete;

  /// Reads up to `size` bytes into `data`; 0 at the end. Throws TraceError for a read error
  /// or gzip data that is damaged or cut short (after handing out every byte before it).
  std::size_t read(char* data, std::size_t size);
  /// Whether the file is gzip-compressed.
  bool gzip() const { return gz_ != nullptr; }
  /// Bytes handed out so far (uncompressed).
  std::uint64_t offset() const { return offset_; }
  /// Newlines among them (the line being read is lines() + 1).
  std::uint64_t lines() const { return lines_; }
  /// The size on disk when it is a regular file, else 0 (a hint for buffers and progress).
  std::uint64_t size_on_disk() const { return size_on_disk_; }
  /// Bytes of the file on disk consumed so far (for a progress bar; compressed bytes for gzip).
  std::uint64_t disk_offset() const;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
  void* gz_ = nullptr;  // gzFile
  void handed_out(const char* data, std::size_t size);

  std::uint64_t offset_ = 0;
  std::uint64_t lines_ = 0;
  std::uint64_t size_on_disk_ = 0;
};

/// The whole file, gunzipped when it is gzip-compressed (TraceError on failure).
std::string read_trace_file(const std::string& path);
/// Its first `size` bytes (fewer when it is shorter), gunzipped when compressed.
std::string read_trace_file_head(const std::string& path, std::size_t size);

/// Writes a file, gzip-compressed when its name ends in ".gz". Errors are std::runtime_error
/// naming the file and the reason.
class TraceFileWriter {
 public:
  /// Creates or truncates `path`.
  explicit TraceFileWriter(const std::string& path);
  /// Finishes the file (the gzip trailer); errors at this point are lost: call close() to see them.
  ~TraceFileWriter();
  TraceFileWriter(const TraceFileWriter&) = delete;
  TraceFileWriter& operator=(const TraceFileWriter&) = delete;

  void write(std::string_view text);
  /// Hands everything written so far to the OS. For gzip, a (partial) flush point: a reader of the
  /// file, even one cut off right after it, gets every byte written before it.
  void flush();
  /// Finishes the file (flush, gzip trailer, close); throws on a write error. Idempotent.
  void close();
  bool gzip() const { return gz_ != nullptr; }

  /// Plain files only: bytes written so far (the end of the file).
  std::uint64_t end_offset() const { return end_; }
  /// Plain files only: writes `text` over the file from `offset` (which must be at most
  /// end_offset()) in one write(2), then cuts the file after `keep` bytes of it (keep <=
  /// text.size()); writing continues at the new end. Flushes first.
  void overwrite_tail(std::uint64_t offset, std::string_view text, std::size_t keep);
  const std::string& path() const { return path_; }

 private:
  [[noreturn]] void fail(const std::string& what) const;

  std::string path_;
  std::FILE* file_ = nullptr;
  void* gz_ = nullptr;  // gzFile
  std::uint64_t end_ = 0;
  bool dirty_ = false;  // written since the last flush
};

}  // namespace l6470emu
