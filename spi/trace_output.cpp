// TraceOutput for files (stdio or zlib through TraceFileWriter) and streams.
#include "spi/trace_output.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ostream>
#include <stdexcept>

#include "spi/trace_file.hpp"

namespace l6470emu {

void TraceOutput::replace_tail(std::uint64_t, std::string_view) {
  throw std::logic_error(name() + ": this trace output cannot be rewritten");
}

namespace {

class FileOutput final : public TraceOutput {
 public:
  FileOutput(const std::string& path, TraceFlushPolicy policy) : file_(path), policy_(std::move(policy)) {
    if (policy_.clock) last_flush_ns_ = policy_.clock();
  }
  void append(std::string_view text) override {
    append_run_progress(text);
    news_ = true;
  }
  void append_run_progress(std::string_view text) override {
    file_.write(text);
    unflushed_ += text.size();
  }
  void event_end() override {
    if (!file_.gzip()) {
      if (policy_.plain_every_event) file_.flush();
      return;
    }
    if (unflushed_ == 0) return;
    // The header leaves at once: a killed recording is a trace from its start.
    if (!flushed_once_ || unflushed_ >= policy_.gzip_bytes || interval_passed()) flush();
  }
  void flush_if_due() override {
    if (unflushed_ != 0 && (!file_.gzip() || interval_passed())) flush();
  }
  std::optional<bool> flush_due() const override {
    if (!file_.gzip() || !policy_.clock) return std::nullopt;
    return !flushed_once_ || unflushed_ >= policy_.gzip_bytes || interval_passed();
  }
  std::uint64_t size() const override { return file_.end_offset(); }
  bool rewritable() const override { return !file_.gzip(); }
  void replace_tail(std::uint64_t offset, std::string_view text) override {
    // One pwrite(2) of a few bytes, then the cut: a kill leaves the old bytes or the new ones.
    file_.overwrite_tail(offset, text, text.size());
  }
  void close() override { file_.close(); }
  const std::string& name() const override { return file_.path(); }

 private:
  /// The time between flushes: the policy's, or longer while only a run's progress is new.
  std::int64_t interval() const { return news_ ? policy_.gzip_interval_ns : quiet_interval_ns_; }
  bool interval_passed() const { return policy_.clock && policy_.clock() - last_flush_ns_ >= interval(); }
  void flush() {
    file_.flush();
    unflushed_ = 0;
    flushed_once_ = true;
    // Twice as long after each flush that took only a run's progress, back to the policy's after any other.
    quiet_interval_ns_ = news_ ? policy_.gzip_interval_ns
                               : std::max(policy_.gzip_interval_ns,
                                          std::min(2 * quiet_interval_ns_, policy_.gzip_quiet_interval_ns));
    news_ = false;
    if (policy_.clock) last_flush_ns_ = policy_.clock();
  }

  TraceFileWriter file_;
  TraceFlushPolicy policy_;
  std::uint64_t unflushed_ = 0;
  bool flushed_once_ = false;
  bool news_ = false;  // text other than a run's progress since the last flush
  // The interval while only a run's progress is new: doubled by each flush that took only that.
  std::int64_t quiet_interval_ns_ = policy_.gzip_interval_ns;
  std::int64_t last_flush_ns_ = 0;
};

class StreamOutput final : public TraceOutput {
 public:
  StreamOutput(std::ostream& out, std::string name, bool flush_each_event)
      : out_(out), name_(std::move(name)), flush_(flush_each_event) {}
  void append(std::string_view text) override {
    errno = 0;
    out_.write(text.data(), static_cast<std::streamsize>(text.size()));
    check();
    size_ += text.size();
  }
  void event_end() override {
    if (!flush_) return;
    errno = 0;
    out_.flush();
    check();
  }
  std::uint64_t size() const override { return size_; }
  void close() override {
    errno = 0;
    out_.flush();
    check();
  }
  const std::string& name() const override { return name_; }

 private:
  /// Throws when the stream has failed; errno was cleared before the write, so a value now is its reason.
  void check() const {
    if (out_) return;
    const int e = errno;
    throw std::runtime_error(name_ + ": write failed" + (e != 0 ? std::string(": ") + std::strerror(e) : std::string()));
  }
  std::ostream& out_;
  std::string name_;
  bool flush_;
  std::uint64_t size_ = 0;
};

}  // namespace

std::unique_ptr<TraceOutput> open_trace_file_output(const std::string& path, TraceFlushPolicy policy) {
  return std::make_unique<FileOutput>(path, std::move(policy));
}

std::unique_ptr<TraceOutput> stream_trace_output(std::ostream& out, std::string name, bool flush_each_event) {
  return std::make_unique<StreamOutput>(out, std::move(name), flush_each_event);
}

}  // namespace l6470emu
