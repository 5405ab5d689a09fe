// Backend with the DeviceBoard inside the host process (L6470EMU_CHAIN / L6470EMU_CONFIG); with
// time=virtual the board's time becomes the program's own (virtual_time.hpp).
#include <cstdlib>
#include <mutex>

#include "linux/preload/backend.hpp"
#include "linux/preload/check_exit.hpp"
#include "linux/preload/coverage.hpp"
#include "linux/preload/progress.hpp"
#include "linux/preload/run.hpp"
#include "linux/preload/virtual_time.hpp"

namespace l6470emu::preload {
namespace {

class LocalBackend final : public Backend {
 public:
  explicit LocalBackend(const BoardConfig& config) : log_(config.log), board_(config, log_), trace_(config.trace) {
    start_run(board_);  // `l6470emu run`: the scenario, the time limit, the report at exit
    start_coverage(board_);  // L6470EMU_COVERAGE: merged into its file at exit
    start_progress();        // `run`'s progress line
    if (config.time.virtual_time) {
      // Made when the program starts (its clock is the board's from then on): the trace starts
      // with the first open of a device, so that a child that never opens one (a shell, a
      // helper program, inheriting the environment) does not truncate its parent's trace.
      virtual_time_ = std::make_unique<VirtualHostTime>(board_, config.time);
      install_virtual_time(virtual_time_.get());
    } else {
      start_trace();
    }
  }

  const std::vector<DeviceNode>& nodes() override { return board_.nodes(); }
  NewFile open(std::size_t device, bool cloexec) override {
    if (virtual_time_) std::call_once(trace_started_, [this] { start_trace(); });
    return board_.open(device, cloexec);
  }
  void closed(std::uint64_t handle) override { board_.closed(handle); }
  long ioctl(std::uint64_t handle, unsigned long cmd, std::span<std::uint8_t> arg, NewFile* created, bool) override {
    return board_.ioctl(handle, cmd, arg, created);
  }
  // check=error: a message that broke a rule of the chip ends the run with the report.
  long spi_message(std::uint64_t handle, std::span<const spi_ioc_transfer> xfers, std::span<const std::uint8_t> tx,
                   std::span<std::uint8_t> rx) override {
    run_device_opened();
    std::string report;
    const long r = checked(board_.spi_message(handle, xfers, tx, rx, &report), report);
    if (progress_kept()) progress_message(board_.time().now());
    return r;
  }
  long spi_read(std::uint64_t handle, std::span<std::uint8_t> rx) override {
    run_device_opened();
    std::string report;
    const long r = checked(board_.spi_read(handle, rx, &report), report);
    if (progress_kept()) progress_message(board_.time().now());
    return r;
  }
  long spi_write(std::uint64_t handle, std::span<const std::uint8_t> tx) override {
    run_device_opened();
    std::string report;
    const long r = checked(board_.spi_write(handle, tx, &report), report);
    if (progress_kept()) progress_message(board_.time().now());
    return r;
  }
  std::size_t pwm_chips() override { return board_.chain_count(); }
  std::size_t pwm_channels(std::size_t chain) override { return board_.pwm_channels(chain); }
  long pwm_write(std::size_t chain, int channel, PwmAttr attr, std::string_view text) override {
    return board_.pwm_write(chain, channel, attr, text);
  }
  long pwm_read(std::size_t chain, int channel, PwmAttr attr, std::string& out) override {
    return board_.pwm_read(chain, channel, attr, out);
  }
  // The scheduler's lock before the board's: the scheduler moves the board while holding it.
  void before_fork() override {
    if (virtual_time_) virtual_time_->before_fork();
    board_.mutex().lock();
  }
  void after_fork_parent() override {
    board_.mutex().unlock();
    if (virtual_time_) virtual_time_->after_fork_parent();
  }
  void after_fork_child() override {
    board_.mutex().unlock();
    board_.forget_pump_after_fork();
    board_.forget_recordings_after_fork();
    run_after_fork_child();
    coverage_after_fork_child();
    // The child goes on with its own copy of the board and of its virtual clock.
    if (virtual_time_) virtual_time_->after_fork_child();
  }

 private:
  static long checked(long result, const std::string& report) {
    if (result == kCheckFailed) end_run_for_check(report);
    return result;
  }

  void start_trace() {
    if (trace_.empty()) return;
    if (const std::string error = board_.start_recording_all(trace_); !error.empty()) {
      log_.line("trace not recorded: " + error);
      return;
    }
    // The program's exit finishes the trace (a plain file cut to its length, a gzip file's end).
    // The backend lives until then: it is never destroyed.
    static LocalBackend* recording = nullptr;
    if (recording == nullptr) {
      recording = this;
      std::atexit([] { recording->finish_recordings(); });
    }
  }

  void finish_recordings() {
    // A thread that still holds the board at exit keeps it: the trace is whole as it is (its
    // unwritten end reads as the end), only not cut to its length.
    if (!board_.mutex().try_lock()) return;
    board_.mutex().unlock();
    for (std::size_t c = 0; c < board_.chain_count(); ++c) board_.stop_recording(c);
  }

  DiagnosticLog log_;
  DeviceBoard board_;
  std::string trace_;
  std::once_flag trace_started_;
  std::unique_ptr<VirtualHostTime> virtual_time_;
};

}  // namespace

std::unique_ptr<Backend> make_local_backend(const BoardConfig& config) {
  return std::make_unique<LocalBackend>(config);
}

}  // namespace l6470emu::preload
