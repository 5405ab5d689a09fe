// DeviceBoard: device nodes, open files, spidev messages, and the board's pin edges as line events.
#include <fcntl.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/random.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <sstream>

#include "board/scenario_runner.hpp"
#include "board/trace_recorder.hpp"
#include "linux/recording_path.hpp"
#include "linux/device_board_internal.hpp"

namespace l6470emu {

DeviceBoard::DeviceBoard(const BoardConfig& config, DiagnosticLog& log, HostClock& host)
    : log_(log), board_(config, [&log](std::string_view line) { log.line(line); }, host) {
  board_.set_edge_sink([this](const PinEdge& e) { report_edge(e); });
  // Recordings: plain files through a shared mapping (no system call per event), gzip flushed
  // by size and host time (the coarse clock: it is read on every event, to 200 ms).
  board_.set_trace_output_opener([&host](const std::string& path) {
    return open_host_recording_output(path, [&host] { return host.coarse_monotonic_ns(); });
  });
  unsigned spi_minor = 0;
  for (const ChainConfig& cc : config.chains) {
    auto cd = std::make_unique<ChainDev>();
    const std::size_t ci = chains_.size();
    cd->name = board_.chain_name(ci);
    cd->spi.mode = cc.mode;
    cd->spi.max_speed_hz = cc.max_speed_hz;
    cd->spi.speed_hz = cc.max_speed_hz;
    cd->spi.bufsiz = cc.bufsiz;
    nodes_.push_back({DeviceNode::Type::spidev, cc.path, cd->name, kSpidevMajor, spi_minor++, cc.bufsiz});
    node_target_.push_back(static_cast<int>(ci));
    if (cc.gpiochip) {
      auto g = std::make_unique<GpioDev>();
      g->name = "gpiochip" + std::to_string(*cc.gpiochip);
      g->label = ("l6470emu " + cd->name).substr(0, 31);
      g->chain = ci;
      const std::size_t n = board_.chip_count(ci);
      g->layout.chips = n;
      for (std::size_t k = 0; k < n; ++k) g->layout.dir = g->layout.dir || board_.chain(ci).peek_chip(k).variant().pins.dir;
      g->layout.spi = cc.pins.sck.has_value();  // SPI at the pins: CS, SCK, MOSI, MISO lines after the chips'
      g->lines.resize(g->layout.count());
      for (unsigned off = 0; off < g->lines.size(); ++off) {
        LineDev& l = g->lines[off];
        l.name = g->layout.name(off);
        l.flags = GPIO_V2_LINE_FLAG_INPUT;
        l.out_value = g->layout.spi_line(off) == SpiLine::cs;  // CS idles high (deselected)
      }
      cd->gpio = static_cast<int>(gpios_.size());
      nodes_.push_back({DeviceNode::Type::gpiochip, "/dev/" + g->name, g->name, kGpiochipMajor, *cc.gpiochip, 0});
      node_target_.push_back(static_cast<int>(gpios_.size()));
      gpios_.push_back(std::move(g));
    }
    chains_.push_back(std::move(cd));
  }
  wake_fd_ = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  std::uint64_t seed = 0;
  if (getrandom(&seed, sizeof seed, 0) != static_cast<ssize_t>(sizeof seed)) seed = static_cast<std::uint64_t>(monotonic_ns());
  handle_ids_.seed(seed);
}

DeviceBoard::~DeviceBoard() {
  stop_pump();
  for (auto& [id, h] : handles_)
    if (h->fd >= 0) ::close(h->fd);
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

// ---------------------------------------------------------------- handles

DeviceBoard::Handle* DeviceBoard::find_any(std::uint64_t id) {
  auto it = handles_.find(id);
  return it == handles_.end() ? nullptr : it->second.get();
}

DeviceBoard::Handle* DeviceBoard::find(std::uint64_t id, HandleKind kind) {
  Handle* h = find_any(id);
  return h && h->kind == kind ? h : nullptr;
}

NewFile DeviceBoard::make_handle(HandleKind kind, std::size_t dev, bool cloexec, std::unique_ptr<Handle>& out) {
  int sv[2];
  if (socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) != 0) return {-errno, 0, -1, kind};
  if (!cloexec) fcntl(sv[1], F_SETFD, 0);
  fcntl(sv[0], F_SETFL, O_NONBLOCK);
  out = std::make_unique<Handle>();
  // Handles are unguessable: a daemon client can only name files it was given (a fork()ed
  // child inherits them), never another program's by counting.
  do out->id = handle_ids_(); while (out->id == 0 || handles_.count(out->id));
  out->kind = kind;
  out->fd = sv[0];
  out->dev = dev;
  wake_pump();  // the pump watches every handle's end for the last close
  return {0, out->id, sv[1], kind};
}

NewFile DeviceBoard::open(std::size_t device, bool cloexec) {
  std::lock_guard lock(m_);
  if (device >= nodes_.size()) return {-ENODEV, 0, -1, HandleKind::spidev};
  const int target = node_target_[device];
  std::unique_ptr<Handle> h;
  if (nodes_[device].type == DeviceNode::Type::spidev) {
    NewFile f = make_handle(HandleKind::spidev, static_cast<std::size_t>(target), cloexec, h);
    if (f.result < 0) return f;
    ++chains_[static_cast<std::size_t>(target)]->users;
    handles_.emplace(h->id, std::move(h));
    return f;
  }
  NewFile f = make_handle(HandleKind::gpiochip, static_cast<std::size_t>(target), cloexec, h);
  if (f.result < 0) return f;
  h->watched.assign(gpios_[static_cast<std::size_t>(target)]->lines.size(), false);
  handles_.emplace(h->id, std::move(h));
  return f;
}

void DeviceBoard::closed(std::uint64_t handle) {
  std::lock_guard lock(m_);
  release_if_closed(handle);
}

void DeviceBoard::release_if_closed(std::uint64_t id) {
  Handle* h = find_any(id);
  if (!h) return;
  pollfd p{h->fd, POLLIN, 0};
  if (poll(&p, 1, 0) == 1 && (p.revents & (POLLHUP | POLLERR))) release(*h);
}

void DeviceBoard::release(Handle& h) {
  switch (h.kind) {
    case HandleKind::spidev: {
      ChainDev& c = *chains_[h.dev];
      if (c.users > 0 && --c.users == 0) c.spi.speed_hz = c.spi.max_speed_hz;  // spidev_release
      break;
    }
    case HandleKind::gpiochip:
      break;
    default: {
      GpioDev& g = *gpios_[h.dev];
      for (unsigned off : h.offsets) {
        LineDev& l = g.lines[off];
        if (l.owner != &h) continue;
        if (l.flags & kV2EdgeFlags) watch_line(g, off, false);
        l.owner = nullptr;
        // The kernel keeps the direction and the driven value; edge detection and the label go.
        l.flags &= ~(kV2EdgeFlags | GPIO_V2_LINE_FLAG_EVENT_CLOCK_REALTIME | GPIO_V2_LINE_FLAG_EVENT_CLOCK_HTE);
        l.debounce_us = 0;
        notify_lineinfo(g, off, GPIO_V2_LINE_CHANGED_RELEASED);
      }
      break;
    }
  }
  ::close(h.fd);
  handles_.erase(h.id);
}

// ---------------------------------------------------------------- spidev

long DeviceBoard::spi_message(std::uint64_t handle, std::span<const spi_ioc_transfer> xfers,
                              std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, std::string* check_report,
                              const std::function<bool()>& caller_alive) {
  Tick end = 0;
  const long r = run_spi_message(handle, xfers, tx, rx, end, check_report, caller_alive);
  if (r >= 0) wait_for(end);  // the call takes the message's bus time, as a kernel transfer does
  return r;
}

CheckConfig DeviceBoard::check_config() {
  std::lock_guard lock(m_);
  return board_.sanitizer().config();
}

void DeviceBoard::set_check_config(const CheckConfig& config) {
  std::lock_guard lock(m_);
  board_.sanitizer().set_config(config);
}

void DeviceBoard::wait_for(Tick tick) {
  // Virtual time with nobody else to wait for: the bus time simply passes (and edges with it).
  if (time().is_virtual() && !time().waiter()) {
    advance_to(tick);
    return;
  }
  time().wait_until(tick);
}

void DeviceBoard::wait_for_bus(std::unique_lock<std::mutex>& lock, unsigned bus) {
  if (sliced_in_flight_ == 0) return;  // the usual case: no lookup
  bus_released_.wait(lock, [&] { return !bus_owned_[bus]; });
}

long DeviceBoard::run_spi_message(std::uint64_t handle, std::span<const spi_ioc_transfer> xfers,
                                  std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, Tick& end,
                                  std::string* check_report, const std::function<bool()>& caller_alive) {
  std::unique_lock lock(m_);
  Handle* h = find(handle, HandleKind::spidev);
  if (!h) return -EBADF;
  if (xfers.empty()) return 0;  // spidev answers SPI_IOC_MESSAGE(0) without touching the bus
  const std::size_t chain = h->dev;
  ChainDev& c = *chains_[chain];
  const long total = validate_spidev_message(c.spi, xfers);
  if (total < 0) return total;
  if (tx.size() != spidev_tx_bytes(xfers) || rx.size() != spidev_rx_bytes(xfers)) return -EFAULT;
  // The settings as they are now: the message keeps them even if they change while it is sliced.
  const SpidevSettings settings = c.spi;
  const unsigned bus = board_.chain_config(chain).bus;
  wait_for_bus(lock, bus);
  thread_local SpidevWireMessage message;  // its buffers keep their capacity from one message to the next
  message.prepare(settings, xfers, tx);
  // The message starts when the bus is free: now, or when the message before it on this bus ends
  // (its caller may still be waiting for that end). The board runs the bus as a host with the
  // node's settings drives it (its sanitizer names what the chip cannot work with); spidev says
  // what to clock.
  const WireSettings wire = spidev_wire_settings(settings);
  if (scenario_ && !time().is_virtual()) scenario_->poll();  // `run`'s scenario: steps due by now
  const bool sliced = caller_alive && !time().is_virtual() && message.bus_ticks() > kBusSliceTicks;
  if (!sliced) {
    message.run(board_.begin_transfer(chain, wire), kNever);
    end = board_.end_transfer(chain);
    message.finish(rx);
    if (board_.has_watched_pins(chain)) wake_pump();
    return finish_spi_message(chain, xfers, tx, rx, end, total, check_report);
  }
  // A long message of a caller that may die: the bus is the message's until it ends or is given
  // up; a slice at a time, the caller sleeping until half a slice before each slice's end (so the
  // next follows back to back, as in one piece) and asking after the caller in between.
  ++sliced_in_flight_;
  bus_owned_[bus] = true;
  struct Owner {
    DeviceBoard& b;
    std::unique_lock<std::mutex>& lock;
    unsigned bus;
    ~Owner() {
      if (!lock.owns_lock()) lock.lock();
      b.bus_owned_[bus] = false;
      --b.sliced_in_flight_;
      b.bus_released_.notify_all();
    }
  } owner{*this, lock, bus};
  for (SpiDevice* dev = &board_.begin_transfer(chain, wire);;) {
    const bool done = message.run(*dev, kBusSliceTicks);
    end = board_.end_transfer(chain);
    if (board_.has_watched_pins(chain)) wake_pump();
    if (done) break;
    lock.unlock();
    wait_for(end > kBusSliceTicks / 2 ? end - kBusSliceTicks / 2 : 0);
    const bool alive = caller_alive();
    lock.lock();
    dev = &board_.begin_transfer(chain, wire);
    if (!alive) {
      // Given up: CS rises now (the board's time when it was noticed), the bus is free from now.
      message.abandon(*dev);
      end = board_.end_transfer(chain);
      return -EPIPE;
    }
  }
  message.finish(rx);
  return finish_spi_message(chain, xfers, tx, rx, end, total, check_report);
}

long DeviceBoard::finish_spi_message(std::size_t chain, std::span<const spi_ioc_transfer> xfers,
                                     std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, Tick end,
                                     long total, std::string* check_report) {
  if (scenario_) scenario_->after_transfer();  // `run`'s scenario: steps the message triggered
  if (observer_) observer_(chain, xfers, tx, rx, end);
  if (board_.sanitizer().failed()) {
    // check=error: the run ends here. The message happened (the chips took it as they would);
    // the caller gets the report instead of its result.
    std::optional<std::string> report = board_.take_check_failure();
    if (check_report == nullptr) {
      // Nobody to end (a kernel node's caller): the report goes to the log, the call fails.
      log_.line(report->substr(report->find("driver sanitizer")));
      if (!first_unended_check_failure_) first_unended_check_failure_ = std::move(*report);
      return -EIO;
    }
    *check_report = std::move(*report);
    return kCheckFailed;
  }
  return total;
}

long DeviceBoard::spi_read(std::uint64_t handle, std::span<std::uint8_t> rx, std::string* check_report,
                           const std::function<bool()>& caller_alive) {
  spi_ioc_transfer x{};
  x.rx_buf = 1;
  x.len = static_cast<std::uint32_t>(rx.size());
  {
    std::lock_guard lock(m_);
    Handle* h = find(handle, HandleKind::spidev);
    if (!h) return -EBADF;
    if (rx.size() > chains_[h->dev]->spi.bufsiz) return -EMSGSIZE;
  }
  return spi_message(handle, std::span<const spi_ioc_transfer>(&x, 1), {}, rx, check_report, caller_alive);
}

long DeviceBoard::spi_write(std::uint64_t handle, std::span<const std::uint8_t> tx, std::string* check_report,
                            const std::function<bool()>& caller_alive) {
  spi_ioc_transfer x{};
  x.tx_buf = 1;
  x.len = static_cast<std::uint32_t>(tx.size());
  {
    std::lock_guard lock(m_);
    Handle* h = find(handle, HandleKind::spidev);
    if (!h) return -EBADF;
    if (tx.size() > chains_[h->dev]->spi.bufsiz) return -EMSGSIZE;
  }
  return spi_message(handle, std::span<const spi_ioc_transfer>(&x, 1), tx, {}, check_report, caller_alive);
}

long DeviceBoard::ioctl(std::uint64_t handle, unsigned long cmd, std::span<std::uint8_t> arg, NewFile* created) {
  Tick lasts_to = 0;
  long r = 0;
  {
    std::lock_guard lock(m_);
    r = locked_ioctl(handle, cmd, arg, created, lasts_to);
  }
  if (lasts_to != 0) wait_for(lasts_to);  // a set of SPI lines takes its time (kSpiLineSetTicks)
  return r;
}

long DeviceBoard::locked_ioctl(std::uint64_t handle, unsigned long cmd, std::span<std::uint8_t> arg, NewFile* created,
                               Tick& lasts_to) {
  Handle* h = find_any(handle);
  if (!h) return -EBADF;
  if (h->kind == HandleKind::spidev) {
    ChainDev& c = *chains_[h->dev];
    std::uint32_t v = 0;
    const std::size_t n = std::min<std::size_t>(arg.size(), sizeof v);
    if (_IOC_DIR(cmd) & _IOC_WRITE) {
      std::uint8_t b[4] = {};
      std::copy_n(arg.data(), n, b);
      v = n == 1 ? b[0] : static_cast<std::uint32_t>(b[0] | b[1] << 8 | b[2] << 16 | static_cast<std::uint32_t>(b[3]) << 24);
    }
    if (_IOC_TYPE(cmd) != SPI_IOC_MAGIC) return -ENOTTY;
    const long r = spidev_settings_ioctl(c.spi, cmd, v);
    if (r < 0) return r;
    if (_IOC_DIR(cmd) & _IOC_READ)
      for (std::size_t i = 0; i < n; ++i) arg[i] = static_cast<std::uint8_t>(v >> (8 * i));
    return r;
  }
  if (h->kind == HandleKind::gpiochip) return gpiochip_ioctl(*h, cmd, arg, created);
  return line_ioctl(*h, cmd, arg, lasts_to);
}

// ---------------------------------------------------------------- pin edges as line events

bool DeviceBoard::physical_level(GpioDev& g, unsigned offset) {
  if (g.layout.spi_line(offset)) return spi_line_level(g, offset);
  const LineDev& l = g.lines[offset];
  const Pin p = g.layout.pin_of(offset);
  // The host drives a chip output: it reads its own value.
  if (pin_is_chip_output(p) && (l.flags & GPIO_V2_LINE_FLAG_OUTPUT)) return l.out_value;
  return board_.level(g.chain, g.layout.chip_of(offset), p);
}

void DeviceBoard::set_chip_input(GpioDev& g, unsigned offset, bool level) {
  if (const auto line = g.layout.spi_line(offset)) return set_spi_line(g, *line, level, /*at_request=*/false);
  LineDev& l = g.lines[offset];
  const Pin p = g.layout.pin_of(offset);
  if (pin_is_chip_output(p)) {
    if (l.out_value != level)
      log_.line(g.name + ": the host drives " + l.name + ", an output of the chip (ignored by the chip)");
    l.out_value = level;
    return;
  }
  board_.set_input(g.chain, g.layout.chip_of(offset), p, level);
}

void DeviceBoard::watch_line(GpioDev& g, unsigned offset, bool watched) {
  // Edge detection (which needs an input line) starts from the level the line has now. (Never
  // asked of an SPI line: a request for its edges is refused.)
  if (g.layout.spi_line(offset)) return;
  board_.watch_pin(g.chain, g.layout.chip_of(offset), g.layout.pin_of(offset), watched);
}

void DeviceBoard::report_edge(const PinEdge& e) {
  const ChainDev& c = *chains_[e.chain];
  if (c.gpio < 0) return;
  GpioDev& g = *gpios_[static_cast<std::size_t>(c.gpio)];
  if (!g.layout.has(e.pin)) return;
  const LineDev& l = g.lines[g.layout.offset(e.chip, e.pin)];
  if (!l.owner) return;
  // Edges are reported in logical terms, as the kernel does (active-low swaps them).
  const bool logical_rising = e.level != ((l.flags & GPIO_V2_LINE_FLAG_ACTIVE_LOW) != 0);
  const std::uint64_t want = logical_rising ? GPIO_V2_LINE_FLAG_EDGE_RISING : GPIO_V2_LINE_FLAG_EDGE_FALLING;
  if (l.flags & want) send_line_event(*l.owner, l.index, logical_rising, e.tick);
}

void DeviceBoard::send_line_event(Handle& h, unsigned index, bool rising, Tick tick) {
  GpioDev& g = *gpios_[h.dev];
  const unsigned off = h.offsets[index];
  // The host's clock at the edge's tick (the kernel stamps the edge when it happens).
  std::int64_t ts = time().host_ns_of(tick);
  if (g.lines[off].flags & GPIO_V2_LINE_FLAG_EVENT_CLOCK_REALTIME) ts += time().realtime_offset_ns();
  ssize_t n = 0;
  if (h.kind == HandleKind::line_event_v1) {
    gpioevent_data e{};
    e.timestamp = static_cast<std::uint64_t>(ts);
    e.id = rising ? GPIOEVENT_EVENT_RISING_EDGE : GPIOEVENT_EVENT_FALLING_EDGE;
    n = send(h.fd, &e, sizeof e, MSG_DONTWAIT | MSG_NOSIGNAL);
  } else if (h.kind == HandleKind::line_request_v2) {
    gpio_v2_line_event e{};
    e.timestamp_ns = static_cast<std::uint64_t>(ts);
    e.id = rising ? GPIO_V2_LINE_EVENT_RISING_EDGE : GPIO_V2_LINE_EVENT_FALLING_EDGE;
    e.offset = off;
    e.seqno = static_cast<std::uint32_t>(++h.seqno);
    e.line_seqno = ++h.line_seqno[index];
    n = send(h.fd, &e, sizeof e, MSG_DONTWAIT | MSG_NOSIGNAL);
  } else {
    return;
  }
  if (n >= 0) board_.note_output_edge(g.chain, g.layout.chip_of(off), g.layout.pin_of(off), rising);  // handed to the host
  if (n < 0 && ++h.dropped == 1)
    log_.line(g.name + ": " + g.lines[off].name + ": event queue full, edge events dropped (the host does not read them)");
}

void DeviceBoard::set_message_observer(MessageObserver observer) {
  std::lock_guard lock(m_);
  observer_ = std::move(observer);
}

// ---------------------------------------------------------------- the physical world

std::string DeviceBoard::chain_summary(std::size_t chain) const {
  const ChainDev& c = *chains_.at(chain);
  std::string s = board_.chain_summary(chain);
  if (c.gpio >= 0) s += ", /dev/" + gpios_[static_cast<std::size_t>(c.gpio)]->name;
  return s;
}

int DeviceBoard::find_chain(const std::string& name) const { return board_.find_chain(name); }

void DeviceBoard::with_chain(std::size_t chain, const std::function<void(Chain&)>& f) {
  std::lock_guard lock(m_);
  board_.with_chain(chain, f);
  wake_pump();
}

std::size_t DeviceBoard::spidev_node(std::size_t chain) const {
  for (std::size_t i = 0; i < nodes_.size(); ++i)
    if (nodes_[i].type == DeviceNode::Type::spidev && node_target_[i] == static_cast<int>(chain)) return i;
  return nodes_.size();
}

std::size_t DeviceBoard::chip_count(std::size_t chain) const { return board_.chip_count(chain); }

bool DeviceBoard::drive_pin(std::size_t chain, std::size_t chip, Pin pin, bool level) {
  std::lock_guard lock(m_);
  if (chain >= chains_.size() || pin_is_chip_output(pin)) return false;
  ChainDev& c = *chains_[chain];
  if (chip >= board_.chip_count(chain)) return false;
  if (!variant_has_pin(board_.chain(chain).peek_chip(chip).variant(), pin)) return false;  // DIR on an L6470...
  board_.catch_up(chain);
  if (c.gpio < 0) return board_.set_input(chain, chip, pin, level);
  GpioDev& g = *gpios_[static_cast<std::size_t>(c.gpio)];
  const unsigned off = g.layout.offset(chip, pin);
  if (g.lines[off].owner && (g.lines[off].flags & GPIO_V2_LINE_FLAG_OUTPUT))
    log_.line(g.name + ": " + g.lines[off].name + " is driven by a host program; the physical world overrides it");
  set_chip_input(g, off, level);
  board_.report_changes(chain);
  wake_pump();
  return true;
}

bool DeviceBoard::pin_level(std::size_t chain, std::size_t chip, Pin pin) {
  std::lock_guard lock(m_);
  ChainDev& c = *chains_.at(chain);
  board_.catch_up(chain);
  if (c.gpio >= 0) {
    GpioDev& g = *gpios_[static_cast<std::size_t>(c.gpio)];
    if (g.layout.has(pin)) return physical_level(g, g.layout.offset(chip, pin));
  }
  return board_.level(chain, chip, pin);
}

bool DeviceBoard::advance(Tick ticks) {
  if (!time().is_virtual()) return false;
  std::lock_guard lock(m_);
  return board_.advance(ticks);
}

bool DeviceBoard::advance_to(Tick tick) {
  if (!time().is_virtual()) return false;
  std::lock_guard lock(m_);
  if (scenario_) {
    scenario_->advance_to(tick);
    return true;
  }
  return board_.advance_to(tick);
}

void DeviceBoard::set_scenario(const Scenario& scenario) {
  std::lock_guard lock(m_);
  scenario_.reset();
  scenario_ = std::make_unique<ScenarioRunner>(board_, scenario);
}

bool DeviceBoard::add_scenario_steps(const std::vector<ScenarioStep>& steps) {
  std::lock_guard lock(m_);
  if (!scenario_) return false;
  scenario_->add_steps(steps);
  return true;
}

Tick DeviceBoard::scenario_next_tick() {
  std::lock_guard lock(m_);
  return scenario_ ? scenario_->next_tick() : kNever;
}

bool DeviceBoard::finish_scenario(ScenarioOutcome& out) {
  std::lock_guard lock(m_);
  if (!scenario_) return false;
  scenario_->finish();
  out = scenario_->outcome();
  return true;
}

void DeviceBoard::enable_coverage() {
  std::lock_guard lock(m_);
  board_.enable_coverage();
}

std::optional<CoverageData> DeviceBoard::coverage(bool try_only) {
  std::unique_lock lock(m_, std::defer_lock);
  if (try_only) {
    if (!lock.try_lock()) return std::nullopt;
  } else {
    lock.lock();
  }
  return board_.coverage();
}

std::optional<std::string> DeviceBoard::first_unended_check_failure() {
  std::lock_guard lock(m_);
  return first_unended_check_failure_;
}

Tick DeviceBoard::next_edge_tick() {
  std::lock_guard lock(m_);
  return board_.next_edge_tick();
}

Tick DeviceBoard::now(std::size_t chain) {
  std::lock_guard lock(m_);
  return board_.now(chain);
}

bool DeviceBoard::inject_fault(std::size_t chain, std::size_t chip, TraceFault fault, std::uint8_t value) {
  std::lock_guard lock(m_);
  if (!board_.inject_fault(chain, chip, fault, value)) return false;
  wake_pump();
  return true;
}

bool DeviceBoard::set_axis_load(std::size_t chain, std::size_t chip, const LoadSpec& load) {
  std::lock_guard lock(m_);
  if (!board_.set_axis_load(chain, chip, load)) return false;
  wake_pump();
  return true;
}

// ---------------------------------------------------------------- trace recording

std::string DeviceBoard::start_recording(std::size_t chain, const std::string& path) {
  std::lock_guard lock(m_);
  return board_.start_recording(chain, path);
}

std::string DeviceBoard::start_recording_all(const std::string& path) {
  for (std::size_t i = 0; i < chain_count(); ++i) {
    const std::string error = start_recording(i, trace_path_for_chain(path, chains_[i]->name, chain_count()));
    if (!error.empty()) return error;
  }
  return "";
}

bool DeviceBoard::stop_recording(std::size_t chain, std::string* summary) {
  std::lock_guard lock(m_);
  return board_.stop_recording(chain, summary);
}

std::string DeviceBoard::recording_path(std::size_t chain) {
  std::lock_guard lock(m_);
  return board_.recording_path(chain);
}

void DeviceBoard::forget_recordings_after_fork() {
  // The parent keeps writing its traces; the child's copies must not add lines to them.
  board_.abandon_recordings();
}

std::string DeviceBoard::describe_handles() {
  std::lock_guard lock(m_);
  std::ostringstream o;
  for (std::size_t i = 0; i < chains_.size(); ++i) {
    const ChainDev* c = chains_[i].get();
    o << c->name << ": " << c->users << " open, mode " << (c->spi.mode & 3) << ", " << c->spi.speed_hz << " Hz, "
      << unsigned{c->spi.bits_per_word} << " bits/word" << ((c->spi.mode & SPI_LSB_FIRST) ? ", LSB first" : "")
      << (board_.chain(i).selected() ? ", CS held low" : "") << "\n";
  }
  for (auto& g : gpios_)
    for (unsigned off = 0; off < g->lines.size(); ++off) {
      const LineDev& l = g->lines[off];
      if (!l.owner) continue;
      o << g->name << " line " << off << " (" << l.name << "): requested by \"" << l.owner->consumer << "\" as "
        << ((l.flags & GPIO_V2_LINE_FLAG_OUTPUT) ? "output" : "input")
        << ((l.flags & kV2EdgeFlags) ? " with edge events" : "") << "\n";
    }
  return o.str();
}

}  // namespace l6470emu
