// l6470emu.Board's state: the board, its spidev rules per chain, queued pin edges, log lines.
#include "py_board.hpp"
#include "sanitizer_failure.hpp"

#include <cerrno>
#include <utility>

namespace l6470emu::python {
namespace {

/// Virtual time reads no host clock: the board's time starts at kVirtualMonotonicOrigin and
/// moves only when a call moves it, so every run is the same.
class FixedHostClock final : public HostClock {
 public:
  std::int64_t monotonic_ns() override { return kVirtualMonotonicOrigin; }
  std::int64_t realtime_ns() override { return kVirtualMonotonicOrigin; }
  void sleep_until(std::int64_t) override {}
};

}  // namespace

PyBoard::PyBoard(const BoardConfig& config, const CoverageRequest& coverage)
    : config_(config), clock_(std::make_unique<FixedHostClock>()) {
  for (const ChainConfig& cc : config_.chains) {
    SpidevSettings s;
    s.mode = cc.mode;
    s.max_speed_hz = cc.max_speed_hz;
    s.speed_hz = cc.max_speed_hz;
    s.bufsiz = cc.bufsiz;
    spi_.push_back(s);
  }
  users_.assign(config_.chains.size(), 0);
  const auto keep = [this](std::string_view line) {
    if (log_.size() >= kMaxLogLines) {
      log_.pop_front();
      ++log_dropped_;
    }
    log_.emplace_back(line);
  };
  board_ = std::make_unique<Board>(config_, keep, *clock_);
  // check=warn lines stay in the log and become l6470emu.SanitizerWarning warnings too, as a
  // Chain's do (take_check_lines, after each message).
  board_->sanitizer().set_log([this, keep](std::string_view line) {
    keep(line);
    if (check_lines_.size() < kMaxLogLines) check_lines_.emplace_back(line);
  });
  board_->set_edge_sink([this](const PinEdge& e) { on_edge(e); });
  if (coverage.collect) {
    board_->enable_coverage();
    if (!coverage.path.empty())
      coverage_out_ = std::make_unique<CoverageOutput>(coverage.path, [b = board_.get()] { return b->coverage(); });
  }
}

PyBoard::~PyBoard() {
  coverage_out_.reset();  // merged while the board is there
  for (std::size_t k = 0; k < board_->chain_count(); ++k) board_->stop_recording(k);
}

const std::string& PyBoard::coverage_path() const {
  static const std::string none;
  return coverage_out_ ? coverage_out_->path() : none;
}

void PyBoard::close(std::size_t chain) {
  if (users_.at(chain) > 0 && --users_[chain] == 0) spi_[chain].speed_hz = spi_[chain].max_speed_hz;
}

long PyBoard::message(std::size_t chain, std::span<const spi_ioc_transfer> xfers, std::span<const std::uint8_t> tx,
                      std::span<std::uint8_t> rx) {
  SpidevSettings& s = spi_.at(chain);
  if (xfers.empty()) return 0;
  const long total = validate_spidev_message(s, xfers);
  if (total < 0) return total;
  if (tx.size() != spidev_tx_bytes(xfers) || rx.size() != spidev_rx_bytes(xfers)) return -EFAULT;
  // The mode, bit order and word size travel in the settings to the spidev rules and the board's
  // bus, which decide what the chips see on the wire; its sanitizer names what the chip cannot
  // work with (check=warn: the log; check=error: l6470emu.SanitizerError with the report).
  run_spidev_message(board_->begin_transfer(chain, spidev_wire_settings(s)), s, xfers, tx, rx);
  const Tick end = board_->end_transfer(chain);
  board_->advance_to(end);  // the caller's call takes the message's bus time
  if (auto report = board_->take_check_failure(FailureEnd::raised)) throw SanitizerFailure(*report);
  return total;
}

void PyBoard::watch(std::size_t chain, std::size_t chip, Pin pin, bool on) {
  EdgeQueue& q = edges_[PinKey{chain, chip, static_cast<unsigned>(pin)}];
  if (on) {
    if (q.watchers++ == 0) {
      q.edges.clear();
      q.dropped = 0;
      board_->catch_up(chain);
      board_->watch_pin(chain, chip, pin, true);
    }
  } else if (q.watchers > 0 && --q.watchers == 0) {
    board_->watch_pin(chain, chip, pin, false);
    q.edges.clear();
  }
}

void PyBoard::on_edge(const PinEdge& e) {
  auto it = edges_.find(PinKey{e.chain, e.chip, static_cast<unsigned>(e.pin)});
  if (it == edges_.end() || it->second.watchers == 0) return;
  EdgeQueue& q = it->second;
  if (q.edges.size() >= kMaxEdgesPerPin) {
    q.edges.pop_front();
    ++q.dropped;
  }
  q.edges.emplace_back(e.tick, e.level);
}

std::vector<std::pair<Tick, bool>> PyBoard::take_edges(std::size_t chain, std::size_t chip, Pin pin,
                                                       std::uint64_t& dropped) {
  auto it = edges_.find(PinKey{chain, chip, static_cast<unsigned>(pin)});
  if (it == edges_.end()) return {};
  std::vector<std::pair<Tick, bool>> out(it->second.edges.begin(), it->second.edges.end());
  it->second.edges.clear();
  dropped += std::exchange(it->second.dropped, 0);
  return out;
}

bool PyBoard::has_edges(std::size_t chain, std::size_t chip, Pin pin) const {
  auto it = edges_.find(PinKey{chain, chip, static_cast<unsigned>(pin)});
  return it != edges_.end() && !it->second.edges.empty();
}

bool PyBoard::wait_edge(std::size_t chain, std::size_t chip, Pin pin, Tick deadline) {
  for (;;) {
    if (has_edges(chain, chip, pin)) return true;
    const Tick now = board_->time().now();
    if (now >= deadline) return false;
    // The next change of any watched output; an input only changes when a call drives it.
    const Tick next = board_->next_edge_tick();
    if (has_edges(chain, chip, pin)) return true;  // found while catching up
    if (next == kNever || next > deadline) {
      board_->advance_to(deadline);
      return has_edges(chain, chip, pin);
    }
    board_->advance_to(next > now ? next : now + 1);
  }
}

std::vector<std::string> PyBoard::take_log(std::uint64_t& dropped) {
  std::vector<std::string> out(log_.begin(), log_.end());
  log_.clear();
  dropped = std::exchange(log_dropped_, 0);
  return out;
}

}  // namespace l6470emu::python
