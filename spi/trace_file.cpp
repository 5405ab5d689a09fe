// Plain and gzip trace files through zlib's gz* calls: the reader checks the magic bytes
// itself (a ".gz" name proves nothing), the writer flushes on request so a recording
// that is killed stays readable up to its last flush.
#include "spi/trace_file.hpp"

#include "spi/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <stdexcept>

#include "spi/input_file.hpp"
#include "spi/trace.hpp"

namespace l6470emu {
namespace {

gzFile as_gz(void* p) { return static_cast<gzFile>(p); }

std::string errno_text() { return std::strerror(errno); }

/// zlib's message without the "<fd:3>: " it puts in front when the file was opened by descriptor.
std::string zlib_message(const char* message) {
  std::string_view m = message != nullptr && *message != '\0' ? message : "unknown error";
  if (m.rfind("<fd:", 0) == 0) {
    if (const std::size_t end = m.find(">: "); end != std::string_view::npos) m.remove_prefix(end + 3);
  }
  return std::string(m);
}

}  // namespace

bool starts_with_gzip_magic(std::string_view head) {
  return head.size() >= 2 && static_cast<unsigned char>(head[0]) == 0x1F && static_cast<unsigned char>(head[1]) == 0x8B;
}

bool gzip_file_name(std::string_view path) { return path.size() > 3 && path.substr(path.size() - 3) == ".gz"; }

std::string_view without_gz(std::string_view path) {
  return gzip_file_name(path) ? path.substr(0, path.size() - 3) : path;
}

// ---------------------------------------------------------------- reader

TraceFileReader::TraceFileReader(const std::string& path) : path_(path) {
  // A device (/dev/zero) or a FIFO nobody writes to would block or never end: refused.
  std::string why;
  fd_ = open_input_file(path, why);
  if (fd_ < 0) throw TraceError(path, 0, errno ? "cannot open: " + errno_text() : "cannot read: it " + why);
  struct stat st {};
  if (fstat(fd_, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) size_on_disk_ = static_cast<std::uint64_t>(st.st_size);
  // The magic, without consuming it (pread leaves the offset alone; pipes are read plain).
  char magic[2];
  const ssize_t got = pread(fd_, magic, 2, 0);
  if (got == 2 && starts_with_gzip_magic(std::string_view(magic, 2))) {
    gz_ = gzdopen(fd_, "rb");
    if (gz_ == nullptr) {
      ::close(fd_);
      throw TraceError(path, 0, "cannot open gzip data: out of memory");
    }
    fd_ = -1;  // zlib owns it now
    gzbuffer(as_gz(gz_), 1 << 15);  // reads of 64 KiB (2x this) go straight to the caller: see read()
  }
}

TraceFileReader::~TraceFileReader() {
  if (gz_ != nullptr) gzclose_r(as_gz(gz_));
  if (fd_ >= 0) ::close(fd_);
}

std::uint64_t TraceFileReader::disk_offset() const {
  if (gz_ == nullptr) return offset_;
  const z_off_t o = gzoffset(as_gz(gz_));
  return o > 0 ? static_cast<std::uint64_t>(o) : 0;
}

std::size_t TraceFileReader::read(char* data, std::size_t size) {
  if (size == 0) return 0;
  if (gz_ == nullptr) {
    for (;;) {
      const ssize_t got = ::read(fd_, data, size);
      if (got >= 0) {
        handed_out(data, static_cast<std::size_t>(got));
        return static_cast<std::size_t>(got);
      }
      if (errno != EINTR)
        throw TraceError(path_, lines_ + 1, "read error after " + std::to_string(offset_) + " bytes: " + errno_text());
    }
  }
  // gzread hands out nothing of a call that meets damaged data (a bad check value is found
  // only at the end): small calls keep the bytes before the damage, and the line it names, close.
  constexpr unsigned kMaxGzRead = 1u << 16;
  const unsigned want = size > kMaxGzRead ? kMaxGzRead : static_cast<unsigned>(size);
  const int got = gzread(as_gz(gz_), data, want);
  int code = Z_OK;
  const char* message = gzerror(as_gz(gz_), &code);
  if (got > 0) {
    handed_out(data, static_cast<std::size_t>(got));
    return static_cast<std::size_t>(got);
  }
  if (code == Z_OK || code == Z_STREAM_END) return 0;
  // The line is the (uncompressed) one the damage falls in: every line before it was handed out.
  const std::string at = std::to_string(offset_) + " bytes of uncompressed data (compressed byte " +
                         std::to_string(disk_offset()) + " of " + std::to_string(size_on_disk_) + ")";
  if (code == Z_BUF_ERROR)
    throw TraceError(path_, lines_ + 1, "the gzip data ends early, after " + at +
                                            ": a truncated file, or a recording that was stopped before it was closed");
  if (code == Z_ERRNO) throw TraceError(path_, lines_ + 1, "read error after " + at + ": " + errno_text());
  throw TraceError(path_, lines_ + 1, "damaged gzip data after " + at + ": " + zlib_message(message));
}

void TraceFileReader::handed_out(const char* data, std::size_t size) {
  offset_ += size;
  lines_ += static_cast<std::uint64_t>(std::count(data, data + size, '\n'));
}

std::string read_trace_file(const std::string& path) {
  TraceFileReader in(path);
  std::string text;
  if (in.size_on_disk() > 0 && !in.gzip()) text.reserve(static_cast<std::size_t>(in.size_on_disk()));
  char buf[1 << 16];
  for (;;) {
    const std::size_t got = in.read(buf, sizeof buf);
    if (got == 0) break;
    text.append(buf, got);
  }
  return text;
}

std::string read_trace_file_head(const std::string& path, std::size_t size) {
  TraceFileReader in(path);
  std::string head(size, '\0');
  std::size_t have = 0;
  while (have < size) {
    std::size_t got = 0;
    try {
      got = in.read(head.data() + have, size - have);
    } catch (const TraceError&) {
      if (have == 0) throw;
      break;  // what came before a damaged part is enough to recognise a format; reading reports it
    }
    if (got == 0) break;
    have += got;
  }
  head.resize(have);
  return head;
}

// ---------------------------------------------------------------- writer

TraceFileWriter::TraceFileWriter(const std::string& path) : path_(path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(path + ": cannot create: " + errno_text());
  if (gzip_file_name(path)) {
    gz_ = gzdopen(fd, "wb6");
    if (gz_ == nullptr) {
      ::close(fd);
      throw std::runtime_error(path + ": cannot start gzip compression: out of memory");
    }
    gzbuffer(as_gz(gz_), 1 << 16);
    return;
  }
  file_ = fdopen(fd, "wb");
  if (file_ == nullptr) {
    ::close(fd);
    throw std::runtime_error(path + ": cannot create: " + errno_text());
  }
  // Big enough that a line of a long frame leaves in one write.
  std::setvbuf(file_, nullptr, _IOFBF, 1 << 16);
}

TraceFileWriter::~TraceFileWriter() {
  try {
    close();
  } catch (...) {
  }
}

void TraceFileWriter::fail(const std::string& what) const {
  throw std::runtime_error(path_ + ": " + what);
}

void TraceFileWriter::write(std::string_view text) {
  if (text.empty()) return;
  if (gz_ != nullptr) {
    if (gzwrite(as_gz(gz_), text.data(), static_cast<unsigned>(text.size())) != static_cast<int>(text.size())) {
      int code = Z_OK;
      const char* m = gzerror(as_gz(gz_), &code);
      fail(std::string("write failed: ") + (code == Z_ERRNO ? errno_text() : m ? m : "gzip error"));
    }
  } else if (file_ != nullptr) {
    if (std::fwrite(text.data(), 1, text.size(), file_) != text.size()) fail("write failed: " + errno_text());
  } else {
    fail("write after close");
  }
  end_ += text.size();
  dirty_ = true;
}

void TraceFileWriter::flush() {
  if (!dirty_) return;
  dirty_ = false;
  if (gz_ != nullptr) {
    // A partial flush: everything so far decodable, ended by an empty 10-bit block rather than
    // a sync flush's 5-byte byte-aligned marker (a recording flushes every 200 ms).
    if (gzflush(as_gz(gz_), Z_PARTIAL_FLUSH) != Z_OK) fail("write failed: " + errno_text());
  } else if (file_ != nullptr) {
    if (std::fflush(file_) != 0) fail("write failed: " + errno_text());
  }
}

void TraceFileWriter::close() {
  if (gz_ != nullptr) {
    const int r = gzclose_w(as_gz(gz_));
    gz_ = nullptr;
    if (r != Z_OK) fail("write failed while finishing the gzip data: " + errno_text());
  }
  if (file_ != nullptr) {
    const int r = std::fclose(file_);
    file_ = nullptr;
    if (r != 0) fail("write failed: " + errno_text());
  }
}

void TraceFileWriter::overwrite_tail(std::uint64_t offset, std::string_view text, std::size_t keep) {
  if (file_ == nullptr || offset > end_ || keep > text.size())
    throw std::logic_error("TraceFileWriter::overwrite_tail on a gzip or closed file, or past its end");
  flush();
  const int fd = fileno(file_);
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = pwrite(fd, text.data() + done, text.size() - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("write failed: " + errno_text());
    done += static_cast<std::size_t>(n);
  }
  const std::uint64_t new_end = offset + keep;
  if (new_end < std::max<std::uint64_t>(end_, offset + text.size()) && ftruncate(fd, static_cast<off_t>(new_end)) != 0)
    fail("cannot cut the file: " + errno_text());
  if (std::fseek(file_, static_cast<long>(new_end), SEEK_SET) != 0) fail("seek failed: " + errno_text());
  end_ = new_end;
}

}  // namespace l6470emu
