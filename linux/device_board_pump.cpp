// DeviceBoard: the pump thread. In wall-clock mode it sleeps until the next BUSY/FLAG edge a
// watched line will see and delivers it on time; in every mode it notices host ends of
// handles closed elsewhere (a killed client, a forked child's last close) and releases them.
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <new>

#include "linux/device_board_internal.hpp"
#include "spi/recording_output.hpp"

namespace l6470emu {

void DeviceBoard::start_pump() {
  std::lock_guard lock(m_);
  if (pump_running_) return;
  pump_stop_ = false;
  pump_running_ = true;
  pump_ = std::thread([this] { pump_loop(); });
}

void DeviceBoard::stop_pump() {
  {
    std::lock_guard lock(m_);
    if (!pump_running_) return;
    pump_stop_ = true;
  }
  wake_pump();
  if (pump_.joinable()) pump_.join();
  std::lock_guard lock(m_);
  pump_running_ = false;
}

void DeviceBoard::forget_pump_after_fork() {
  // The thread does not exist in the child; drop the handle without touching it.
  new (&pump_) std::thread();
  pump_running_ = false;
}

void DeviceBoard::wake_pump() {
  if (!pump_running_ || wake_fd_ < 0) return;
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(wake_fd_, &one, sizeof one);
}

void DeviceBoard::pump_loop() {
  std::vector<pollfd> fds;
  std::vector<std::uint64_t> ids;
  for (;;) {
    std::int64_t deadline = INT64_MAX;
    fds.clear();
    ids.clear();
    {
      std::lock_guard lock(m_);
      if (pump_stop_) return;
      // A gzip recording gone quiet still hands its data to the OS on time.
      board_.flush_recordings();
      for (std::size_t i = 0; i < chains_.size(); ++i) {
        if (!board_.recording_path(i).empty())
          deadline = std::min(deadline, time().host().monotonic_ns() + kRecordingGzipFlushNs);
        if (chains_[i]->gpio < 0 || !board_.has_watched_pins(i)) continue;
        board_.catch_up(i);
        if (time().is_virtual()) continue;
        const Tick t = board_.predict_edge_tick(i);
        if (t != kNever) deadline = std::min(deadline, time().host_ns_of(t));
      }
      fds.push_back({wake_fd_, POLLIN, 0});
      for (auto& [id, h] : handles_) {
        fds.push_back({h->fd, 0, 0});  // POLLHUP is always reported
        ids.push_back(id);
      }
    }
    timespec ts{};
    timespec* tsp = nullptr;
    if (deadline != INT64_MAX) {
      std::int64_t wait = deadline - time().host().monotonic_ns();
      if (wait < 0) wait = 0;
      // The kernel lets a poll timeout run late by 0.1 % of its length (select_estimate_accuracy):
      // 0.6 ms for a 0.6 s move. Wake early and plan again; the last short wait is nearly exact.
      if (wait > 1'000'000) wait -= std::max<std::int64_t>(1'000'000, wait / 500);
      ts.tv_sec = wait / 1'000'000'000;
      ts.tv_nsec = wait % 1'000'000'000;
      tsp = &ts;
    }
    const int n = ppoll(fds.data(), fds.size(), tsp, nullptr);
    if (n <= 0) continue;
    if (fds[0].revents & POLLIN) {
      std::uint64_t v;
      while (::read(wake_fd_, &v, sizeof v) == sizeof v) {
      }
    }
    std::lock_guard lock(m_);
    for (std::size_t i = 1; i < fds.size(); ++i)
      if (fds[i].revents & (POLLHUP | POLLERR)) release_if_closed(ids[i - 1]);
  }
}

}  // namespace l6470emu
