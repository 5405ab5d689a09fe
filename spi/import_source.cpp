// An importer's text from memory or streamed from a file: lines bounded by kMaxTraceLineBytes,
// the buffer never larger than that, a scan for markers and a second pass.
#include "spi/import_source.hpp"

#include <algorithm>
#include <cstring>

#include "spi/trace_file.hpp"

namespace l6470emu::detail {
namespace {

constexpr std::size_t kChunk = std::size_t{1} << 20;
constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";

}  // namespace

ImportSource::ImportSource(std::string_view text, std::string name) : name_(std::move(name)), text_(text) {
  end_ = text_.size();
  eof_ = true;
}

ImportSource::ImportSource(const std::string& path) : name_(path), path_(path) {
  file_ = std::make_unique<TraceFileReader>(path);
  const std::uint64_t size = file_->size_on_disk();
  buffer_.resize(size > 0 && !file_->gzip() ? std::clamp<std::size_t>(static_cast<std::size_t>(size) + 1, 4096, kChunk)
                                            : kChunk);
}

ImportSource::~ImportSource() = default;

bool ImportSource::fill() {
  const std::size_t keep = end_ - begin_;
  if (keep > 0 && begin_ > 0) std::memmove(buffer_.data(), buffer_.data() + begin_, keep);
  begin_ = 0;
  end_ = keep;
  if (keep == buffer_.size()) buffer_.resize(std::min(buffer_.size() * 2, kMaxTraceLineBytes + 2));
  std::size_t got = 0;
  try {
    got = file_->read(buffer_.data() + keep, buffer_.size() - keep);
  } catch (const TraceError& e) {
    // Every complete line before the damage has been handed out: say where it stopped.
    throw TraceError(name_, number_ + 1, e.reason());
  }
  end_ += got;
  if (got == 0) eof_ = true;
  return got > 0;
}

bool ImportSource::next(std::string_view& line) {
  for (;;) {
    const char* data = file_ ? buffer_.data() : text_.data();
    const std::size_t unread = end_ - begin_;
    const void* nl = unread > 0 ? std::memchr(data + begin_, '\n', unread) : nullptr;
    if (nl != nullptr) {
      const auto at = static_cast<std::size_t>(static_cast<const char*>(nl) - data);
      line = std::string_view(data + begin_, at - begin_);
      begin_ = at + 1;
    } else {
      if (unread > kMaxTraceLineBytes) {
        ++number_;
        throw TraceError(name_, number_, line_too_long());
      }
      if (!eof_) {
        fill();
        continue;
      }
      if (unread == 0) return false;
      line = std::string_view(data + begin_, unread);
      begin_ = end_;
      unterminated_ = true;
    }
    if (line.size() > kMaxTraceLineBytes) {
      ++number_;
      throw TraceError(name_, number_, line_too_long());
    }
    ++number_;
    if (report_ && (number_ & 0xFFFF) == 0) report_(progress());
    if (at_start_) {
      at_start_ = false;
      if (line.substr(0, kByteOrderMark.size()) == kByteOrderMark) line.remove_prefix(kByteOrderMark.size());
    }
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return true;
  }
}

bool ImportSource::next_chunk(std::string_view& chunk) {
  if (begin_ == end_) {
    if (eof_) return false;
    begin_ = end_ = 0;
    std::size_t got = 0;
    try {
      got = file_->read(buffer_.data(), buffer_.size());
    } catch (const TraceError& e) {
      throw TraceError(name_, 0, e.reason());
    }
    if (got == 0) {
      eof_ = true;
      return false;
    }
    end_ = got;
  }
  const char* data = file_ ? buffer_.data() : text_.data();
  chunk = std::string_view(data + begin_, end_ - begin_);
  begin_ = end_;
  if (report_) report_(progress());
  return true;
}

void ImportSource::rewind() {
  number_ = 0;
  unterminated_ = false;
  at_start_ = true;
  begin_ = 0;
  if (!file_) {
    end_ = text_.size();
    return;
  }
  file_ = std::make_unique<TraceFileReader>(path_);
  end_ = 0;
  eof_ = false;
}

std::vector<bool> ImportSource::contains(std::span<const std::string_view> needles) {
  std::vector<bool> found(needles.size(), false);
  if (!file_) {
    for (std::size_t i = 0; i < needles.size(); ++i) found[i] = text_.find(needles[i]) != std::string_view::npos;
    rewind();
    return found;
  }
  std::size_t longest = 0;
  for (std::string_view n : needles) longest = std::max(longest, n.size());
  // A window of the file: what was read last, behind the tail of the chunk before (a needle may
  // straddle two chunks).
  TraceFileReader in(path_);
  std::string window;
  std::vector<char> chunk(kChunk);
  std::size_t left = needles.size();
  std::size_t since_newline = 0;  // bytes read since the last newline
  while (left > 0) {
    std::size_t got = 0;
    try {
      got = in.read(chunk.data(), chunk.size());
    } catch (const TraceError&) {
      break;  // the pass that reads the lines says where the damage is
    }
    if (got == 0) break;
    // A line longer than any reader takes ends the look: the pass that reads the lines says so
    // (an endless stream without a newline, such as <(cat /dev/zero), ends here too).
    const std::string_view read(chunk.data(), got);
    const std::size_t last_nl = read.rfind('\n');
    since_newline = last_nl == std::string_view::npos ? since_newline + got : got - 1 - last_nl;
    if (since_newline > kMaxTraceLineBytes) break;
    const std::size_t tail = longest > 0 ? std::min(window.size(), longest - 1) : 0;
    window.erase(0, window.size() - tail);
    window.append(chunk.data(), got);
    for (std::size_t i = 0; i < needles.size(); ++i)
      if (!found[i] && window.find(needles[i]) != std::string::npos) {
        found[i] = true;
        --left;
      }
  }
  rewind();
  return found;
}

bool ImportSource::contains(std::string_view needle) { return contains(std::span<const std::string_view>(&needle, 1))[0]; }

ReadProgress ImportSource::progress() const {
  if (!file_) return {begin_, text_.size()};
  return {file_->disk_offset(), file_->size_on_disk()};
}

}  // namespace l6470emu::detail
