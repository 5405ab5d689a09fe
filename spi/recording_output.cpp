// The mapped recording file: a line becomes visible when its first byte is stored (everything
// after it, and the zero byte that ends the text, are in place before), a `repeat` count when
// the aligned 8-byte word holding it is stored. Readers stop at a line that starts with a zero
// byte (spi/trace_native.cpp), so the file reads as a whole trace at every instant.
#include "spi/recording_output.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "spi/trace_file.hpp"

namespace l6470emu {
namespace {

constexpr std::size_t kFirstChunk = 64 * 1024;
constexpr std::size_t kLargestStep = 64u * 1024 * 1024;

class MappedOutput final : public TraceOutput {
 public:
  MappedOutput(std::string path, int fd) : path_(std::move(path)), fd_(fd) {
    try {
      reserve(kFirstChunk);
    } catch (...) {
      ::close(fd_);
      throw;
    }
  }
  ~MappedOutput() override {
    try {
      close();
    } catch (...) {
    }
  }
  MappedOutput(const MappedOutput&) = delete;
  MappedOutput& operator=(const MappedOutput&) = delete;

  void append(std::string_view text) override {
    if (fd_ < 0) throw std::runtime_error(path_ + ": write after close");
    if (text.empty()) return;
    if (size_ + text.size() + 1 > capacity_) reserve(size_ + text.size() + 1);
    char* at = map_ + size_;
    // The rest of the text and the zero byte after it first, the first byte last: a reader (or a
    // kill) sees the whole text or none of it.
    std::memcpy(at + 1, text.data() + 1, text.size() - 1);
    at[text.size()] = '\0';
    std::atomic_ref<char>(*at).store(text[0], std::memory_order_release);
    size_ += text.size();
  }

  std::uint64_t size() const override { return size_; }
  bool rewritable() const override { return true; }

  void replace_tail(std::uint64_t offset, std::string_view text) override {
    if (fd_ < 0) throw std::runtime_error(path_ + ": write after close");
    if (offset > size_) throw std::logic_error(path_ + ": replace_tail past the end");
    const std::uint64_t word = offset / 8 * 8;
    if (!text.empty() && offset + text.size() < word + 8) {
      // The new bytes and the zero byte that ends the text, in one aligned 8-byte store.
      std::uint64_t value;
      if (offset == word && text.size() == 7 && std::endian::native == std::endian::little) {
        // An open repeat line's count field and newline: two loads that overlap by a byte, put
        // together in a register (bytes stored one by one and read back as a word would wait
        // for the stores).
        std::uint32_t lo, hi;
        std::memcpy(&lo, text.data(), 4);
        std::memcpy(&hi, text.data() + 3, 4);
        value = lo | std::uint64_t{hi >> 8} << 32;
      } else {
        char bytes[8];
        std::memcpy(bytes, map_ + word, 8);
        for (std::size_t i = 0; i < text.size(); ++i) bytes[offset - word + i] = text[i];
        bytes[offset - word + text.size()] = '\0';
        std::memcpy(&value, bytes, 8);
      }
      std::atomic_ref<std::uint64_t>(*reinterpret_cast<std::uint64_t*>(map_ + word))
          .store(value, std::memory_order_release);
      size_ = offset + text.size();
      return;
    }
    // Anything longer: the text ends at `offset` first (a kill there loses the old tail), then
    // the new one is appended.
    std::atomic_ref<char>(map_[offset]).store('\0', std::memory_order_release);
    size_ = offset;
    append(text);
  }

  void close() override {
    if (fd_ < 0) return;
    const int fd = fd_;
    fd_ = -1;
    unmap();
    const bool cut = ftruncate(fd, static_cast<off_t>(size_)) == 0;
    const int cut_errno = errno;
    const bool closed = ::close(fd) == 0;
    if (!cut) throw std::runtime_error(path_ + ": cannot cut the file to its length: " + std::strerror(cut_errno));
    if (!closed) throw std::runtime_error(path_ + ": write failed: " + std::strerror(errno));
  }

  void abandon() override {
    // A forked child's copy: the mapping is shared with the parent, which goes on writing.
    if (fd_ < 0) return;
    unmap();
    ::close(fd_);
    fd_ = -1;
  }

  const std::string& name() const override { return path_; }

 private:
  void unmap() {
    if (map_ != nullptr) munmap(map_, capacity_);
    map_ = nullptr;
  }

  /// Makes the file and the mapping at least `bytes` long.
  void reserve(std::size_t bytes) {
    if (bytes <= capacity_) return;
    const std::size_t step = std::min(std::max(capacity_, kFirstChunk), kLargestStep);
    std::size_t wanted = std::max(bytes, capacity_ + step);
    const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    wanted = (wanted + page - 1) / page * page;
    // The blocks are taken now: a full disk is an error here, not a SIGBUS at a later store.
    const int e = posix_fallocate(fd_, 0, static_cast<off_t>(wanted));
    if (e == EOPNOTSUPP || e == EINVAL) {
      if (ftruncate(fd_, static_cast<off_t>(wanted)) != 0)
        throw std::runtime_error(path_ + ": cannot grow the file: " + std::strerror(errno));
    } else if (e != 0) {
      throw std::runtime_error(path_ + ": cannot grow the file to " + std::to_string(wanted) + " bytes: " + std::strerror(e));
    }
    void* m = map_ == nullptr ? mmap(nullptr, wanted, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0)
                              : mremap(map_, capacity_, wanted, MREMAP_MAYMOVE);
    if (m == MAP_FAILED) throw std::runtime_error(path_ + ": cannot map the file: " + std::strerror(errno));
    map_ = static_cast<char*>(m);
    capacity_ = wanted;
  }

  std::string path_;
  int fd_ = -1;
  char* map_ = nullptr;
  std::size_t capacity_ = 0;
  std::uint64_t size_ = 0;
};

}  // namespace

std::unique_ptr<TraceOutput> open_mapped_trace_output(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(path + ": cannot create: " + std::strerror(errno));
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return nullptr;
  }
  if (ftruncate(fd, 0) != 0) {
    const int e = errno;
    ::close(fd);
    throw std::runtime_error(path + ": cannot truncate: " + std::strerror(e));
  }
  return std::make_unique<MappedOutput>(path, fd);
}

std::unique_ptr<TraceOutput> open_recording_output(const std::string& path, std::function<std::int64_t()> clock) {
  if (gzip_file_name(path)) {
    TraceFlushPolicy policy;
    policy.gzip_bytes = kRecordingGzipFlushBytes;
    policy.gzip_interval_ns = kRecordingGzipFlushNs;
    policy.clock = std::move(clock);
    return open_trace_file_output(path, std::move(policy));
  }
  if (auto mapped = open_mapped_trace_output(path)) return mapped;
  return open_trace_file_output(path);
}

}  // namespace l6470emu
