// Board: device nodes, open files, spidev messages, time and pin edges.
#include <fcntl.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/random.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cerrno>
#include <sstream>

#include "linux/board_internal.hpp"
#include "spi/message.hpp"

namespace l6470emu {

/// How often each kind of chip diagnostic is logged in full per chip.
constexpr std::uint64_t kDiagnosticRepeats = 10;

Board::Board(const BoardConfig& config, DiagnosticLog& log, HostClock& host)
    : log_(log), time_(config.time, host), numbering_(config.numbering) {
  unsigned spi_minor = 0;
  for (const ChainConfig& cc : config.chains) {
    std::vector<Chip> chips;
    chips.reserve(cc.chips.size());
    for (const Variant* v : cc.chips) chips.emplace_back(*v);
    // axis.K counts chips as the board's numbering= does.
    const ChipNumbering axis_numbers(numbering_, chips.size());
    for (const auto& [k, spec] : cc.axes) chips.at(axis_numbers.index_of(k)).attach_axis(spec);
    auto cd = std::make_unique<ChainDev>(cc, std::move(chips));
    cd->name = cc.path.substr(cc.path.rfind('/') + 1);
    cd->spi.mode = cc.mode;
    cd->spi.max_speed_hz = cc.max_speed_hz;
    cd->spi.speed_hz = cc.max_speed_hz;
    cd->spi.bufsiz = cc.bufsiz;
    const std::size_t ci = chains_.size();
    for (std::size_t k = 0; k < cd->chain.size(); ++k) {
      const std::string where = cd->name + ": " + ChipNumbering(numbering_, cd->chain.size()).label(k) + ": ";
      // A driver looping on a bad command must not flood the log: each kind is shown
      // kDiagnosticRepeats times per chip, then counted, with a tally at every power of ten.
      cd->chain.chip(k).set_diagnostic_sink([this, where, seen = std::array<std::uint64_t, 3>{}](const Diagnostic& d) mutable {
        const std::size_t i = d.kind == DiagnosticKind::wrong_cmd ? 0 : d.kind == DiagnosticKind::notperf_cmd ? 1 : 2;
        const char* kind = i == 0 ? "WRONG_CMD" : i == 1 ? "NOTPERF_CMD" : "ignored";
        const std::uint64_t n = ++seen[i];
        if (n < kDiagnosticRepeats) {
          log_.line(where + kind + ": " + d.message);
        } else if (n == kDiagnosticRepeats) {
          log_.line(where + kind + ": " + d.message + "  (further ones of this kind are counted, not shown)");
        } else {
          std::uint64_t p = kDiagnosticRepeats;
          while (p < n && p <= UINT64_MAX / 10) p *= 10;
          if (p == n) log_.line(where + kind + ": " + std::to_string(n) + " so far");
        }
      });
    }
    nodes_.push_back({DeviceNode::Type::spidev, cc.path, cd->name, kSpidevMajor, spi_minor++, cc.bufsiz});
    node_target_.push_back(static_cast<int>(ci));
    if (cc.gpiochip) {
      auto g = std::make_unique<GpioDev>();
      g->name = "gpiochip" + std::to_string(*cc.gpiochip);
      g->label = ("l6470emu " + cd->name).substr(0, 31);
      g->chain = ci;
      const std::size_t n = cd->chain.size();
      g->lines.resize(n * kPinsPerChip);
      for (unsigned off = 0; off < g->lines.size(); ++off) {
        LineDev& l = g->lines[off];
        l.name = line_name(n, off);
        const Pin p = pin_of_line(off);
        l.level = p != Pin::STCK;  // SW open (pulled up), STBY_RST high (running), STCK low
        l.flags = GPIO_V2_LINE_FLAG_INPUT;
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

Board::~Board() {
  stop_pump();
  for (auto& [id, h] : handles_)
    if (h->fd >= 0) ::close(h->fd);
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

// ---------------------------------------------------------------- handles

Board::Handle* Board::find_any(std::uint64_t id) {
  auto it = handles_.find(id);
  return it == handles_.end() ? nullptr : it->second.get();
}

Board::Handle* Board::find(std::uint64_t id, HandleKind kind) {
  Handle* h = find_any(id);
  return h && h->kind == kind ? h : nullptr;
}

NewFile Board::make_handle(HandleKind kind, std::size_t dev, bool cloexec, std::unique_ptr<Handle>& out) {
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

NewFile Board::open(std::size_t device, bool cloexec) {
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

void Board::closed(std::uint64_t handle) {
  std::lock_guard lock(m_);
  release_if_closed(handle);
}

void Board::release_if_closed(std::uint64_t id) {
  Handle* h = find_any(id);
  if (!h) return;
  pollfd p{h->fd, POLLIN, 0};
  if (poll(&p, 1, 0) == 1 && (p.revents & (POLLHUP | POLLERR))) release(*h);
}

void Board::release(Handle& h) {
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
      bool had_edges = false;
      for (unsigned off : h.offsets) {
        LineDev& l = g.lines[off];
        if (l.owner != &h) continue;
        had_edges = had_edges || (l.flags & kV2EdgeFlags);
        l.owner = nullptr;
        // The kernel keeps the direction and the driven value; edge detection and the label go.
        l.flags &= ~(kV2EdgeFlags | GPIO_V2_LINE_FLAG_EVENT_CLOCK_REALTIME | GPIO_V2_LINE_FLAG_EVENT_CLOCK_HTE);
        l.debounce_us = 0;
        notify_lineinfo(g, off, GPIO_V2_LINE_CHANGED_RELEASED);
      }
      if (had_edges) refresh_watch_list(g);
      break;
    }
  }
  ::close(h.fd);
  handles_.erase(h.id);
}

// ---------------------------------------------------------------- spidev

long Board::spi_message(std::uint64_t handle, std::span<const spi_ioc_transfer> xfers, std::span<const std::uint8_t> tx,
                        std::span<std::uint8_t> rx) {
  Tick end = 0;
  const long r = run_spi_message(handle, xfers, tx, rx, end);
  if (r >= 0) wait_for(end);  // the call takes the message's bus time, as a kernel transfer does
  return r;
}

void Board::wait_for(Tick tick) {
  // Virtual time with nobody else to wait for: the bus time simply passes (and edges with it).
  if (time_.is_virtual() && !time_.waiter()) {
    advance_to(tick);
    return;
  }
  time_.wait_until(tick);
}

long Board::run_spi_message(std::uint64_t handle, std::span<const spi_ioc_transfer> xfers,
                            std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, Tick& end) {
  std::lock_guard lock(m_);
  Handle* h = find(handle, HandleKind::spidev);
  if (!h) return -EBADF;
  if (xfers.empty()) return 0;  // spidev answers SPI_IOC_MESSAGE(0) without touching the bus
  ChainDev& c = *chains_[h->dev];
  const long total = validate_spidev_message(c.spi, xfers);
  if (total < 0) return total;
  if (tx.size() != spidev_tx_bytes(xfers) || rx.size() != spidev_rx_bytes(xfers)) return -EFAULT;
  // Settings the chip cannot work with are reported once each (cheap test first: the usual case is clean).
  bool suspicious = (c.spi.mode & (SPI_CPOL | SPI_CPHA | SPI_LSB_FIRST | SPI_CS_HIGH)) != SPI_MODE_3 ||
                    c.spi.speed_hz > kChipMaxSpeedHz || c.spi.bits_per_word != 8;
  for (const auto& x : xfers)
    if (x.speed_hz > kChipMaxSpeedHz || (x.bits_per_word != 0 && x.bits_per_word != 8)) suspicious = true;
  if (suspicious)
    check_spidev_settings_for_chip(c.spi, xfers, c.reported, [&](const std::string& s) { log_.line(c.name + ": " + s); });
  // The message starts when the bus is free: now, or when the message before it on this bus ends
  // (its caller may still be waiting for that end).
  Tick& bus_free = bus_free_[c.config.bus];
  const Tick start = std::max(time_.now(), bus_free);
  if (start > c.chain.now()) advance_chain(c, start);
  record_outputs(c);
  // One controller per bus: a chip-select still held low on another device of the bus is released first.
  for (auto& other : chains_)
    if (other.get() != &c && other->config.bus == c.config.bus && other->chain.selected()) spi_of(*other).deselect();
  run_spidev_message(spi_of(c), c.spi, xfers, tx, rx);
  if (c.gpio >= 0 && !gpios_[static_cast<std::size_t>(c.gpio)]->watched.empty()) {
    emit_changes(c, c.chain.now());
    wake_pump();
  }
  if (observer_) observer_(h->dev, xfers, tx, rx, c.chain.now());
  end = bus_free = c.chain.now();
  return total;
}

long Board::spi_read(std::uint64_t handle, std::span<std::uint8_t> rx) {
  spi_ioc_transfer x{};
  x.rx_buf = 1;
  x.len = static_cast<std::uint32_t>(rx.size());
  {
    std::lock_guard lock(m_);
    Handle* h = find(handle, HandleKind::spidev);
    if (!h) return -EBADF;
    if (rx.size() > chains_[h->dev]->spi.bufsiz) return -EMSGSIZE;
  }
  return spi_message(handle, std::span<const spi_ioc_transfer>(&x, 1), {}, rx);
}

long Board::spi_write(std::uint64_t handle, std::span<const std::uint8_t> tx) {
  spi_ioc_transfer x{};
  x.tx_buf = 1;
  x.len = static_cast<std::uint32_t>(tx.size());
  {
    std::lock_guard lock(m_);
    Handle* h = find(handle, HandleKind::spidev);
    if (!h) return -EBADF;
    if (tx.size() > chains_[h->dev]->spi.bufsiz) return -EMSGSIZE;
  }
  return spi_message(handle, std::span<const spi_ioc_transfer>(&x, 1), tx, {});
}

long Board::ioctl(std::uint64_t handle, unsigned long cmd, std::span<std::uint8_t> arg, NewFile* created) {
  std::lock_guard lock(m_);
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
    if (_IOC_DIR(cmd) & _IOC_READ) {
      for (std::size_t i = 0; i < n; ++i) arg[i] = static_cast<std::uint8_t>(v >> (8 * i));
    } else {
      c.reported = 0;  // new settings: report their problems afresh
    }
    return r;
  }
  if (h->kind == HandleKind::gpiochip) return gpiochip_ioctl(*h, cmd, arg, created);
  return line_ioctl(*h, cmd, arg);
}

// ---------------------------------------------------------------- time and edges

void Board::catch_up(ChainDev& c) {
  const Tick target = time_.now();
  if (target > c.chain.now()) advance_chain(c, target);
}

Tick Board::first_change(ChainDev& c, std::size_t chip, Pin pin, bool level, Tick from, Tick to) {
  auto level_at = [&](Tick t) {
    Chip probe = c.chain.chip(chip);
    probe.set_diagnostic_sink({});
    probe.advance_to(t);
    return pin == Pin::BUSY ? probe.busy_sync_pin() : probe.flag_pin();
  };
  if (level_at(to) == level) return kNever;
  Tick lo = from, hi = to;  // level at lo is `level`, at hi it differs
  while (hi - lo > 1) {
    const Tick mid = lo + (hi - lo) / 2;
    if (level_at(mid) == level)
      lo = mid;
    else
      hi = mid;
  }
  return hi;
}

void Board::advance_chain(ChainDev& c, Tick target) {
  if (c.gpio < 0 || gpios_[static_cast<std::size_t>(c.gpio)]->watched.empty()) {
    c.chain.advance_to(target);
    return;
  }
  GpioDev& g = *gpios_[static_cast<std::size_t>(c.gpio)];
  // Step from edge to edge so that every event carries the tick it happened at.
  for (int guard = 0; guard < 10000 && c.chain.now() < target; ++guard) {
    Tick first = kNever;
    for (unsigned off : g.watched) {
      const Pin p = pin_of_line(off);
      if (!pin_is_chip_output(p) || g.lines[off].owner == nullptr) continue;
      if (g.lines[off].flags & GPIO_V2_LINE_FLAG_OUTPUT) continue;
      const std::size_t k = chip_of_line(off);
      if (c.chain.chip(k).next_event_tick() == kNever) continue;  // nothing moves on its own
      first = std::min(first, first_change(c, k, p, g.lines[off].last, c.chain.now(), target));
    }
    if (first == kNever) {
      c.chain.advance_to(target);
      break;
    }
    c.chain.advance_to(first);
    emit_changes(c, first);
  }
  if (c.chain.now() < target) c.chain.advance_to(target);
}

Tick Board::predict_next_edge(ChainDev& c) {
  if (c.gpio < 0) return kNever;
  GpioDev& g = *gpios_[static_cast<std::size_t>(c.gpio)];
  Tick best = kNever;
  const Tick now = c.chain.now();
  for (unsigned off : g.watched) {
    const Pin p = pin_of_line(off);
    if (!pin_is_chip_output(p) || g.lines[off].owner == nullptr) continue;
    if (g.lines[off].flags & GPIO_V2_LINE_FLAG_OUTPUT) continue;
    const std::size_t k = chip_of_line(off);
    if (c.chain.chip(k).next_event_tick() == kNever) continue;
    // Exponential search forward, then bisection (first_change) inside the bracket.
    Tick lo = now;
    for (Tick step = 64; step < (Tick{1} << 40) && lo < best; step *= 2) {
      const Tick hi = now + step;
      const Tick t = first_change(c, k, p, g.lines[off].last, lo, hi);
      if (t != kNever) {
        best = std::min(best, t);
        break;
      }
      lo = hi;
    }
  }
  return best;
}

bool Board::physical_level(GpioDev& g, unsigned offset) {
  LineDev& l = g.lines[offset];
  const Pin p = pin_of_line(offset);
  if (!pin_is_chip_output(p)) return l.level;
  if (l.flags & GPIO_V2_LINE_FLAG_OUTPUT) return l.out_value;  // the host drives a chip output: it reads its own value
  const Chip& chip = chains_[g.chain]->chain.chip(chip_of_line(offset));
  return p == Pin::BUSY ? chip.busy_sync_pin() : chip.flag_pin();
}

void Board::set_chip_input(GpioDev& g, unsigned offset, bool level) {
  LineDev& l = g.lines[offset];
  const Pin p = pin_of_line(offset);
  if (pin_is_chip_output(p)) {
    if (l.out_value != level)
      log_.line(g.name + ": the host drives " + l.name + ", an output of the chip (ignored by the chip)");
    l.out_value = level;
    return;
  }
  if (l.level == level) return;
  l.level = level;
  apply_input(*chains_[g.chain], chip_of_line(offset), p, level);
}

void Board::refresh_watch_list(GpioDev& g) {
  g.watched.clear();
  for (unsigned off = 0; off < g.lines.size(); ++off) {
    LineDev& l = g.lines[off];
    if (l.owner && (l.flags & kV2EdgeFlags)) {
      g.watched.push_back(off);
    }
  }
}

void Board::emit_changes(ChainDev& c, Tick tick) {
  record_outputs(c);
  if (c.gpio < 0) return;
  GpioDev& g = *gpios_[static_cast<std::size_t>(c.gpio)];
  for (unsigned off : g.watched) {
    LineDev& l = g.lines[off];
    const bool level = physical_level(g, off);
    if (level == l.last) continue;
    l.last = level;
    if (!l.owner) continue;
    // Edges are reported in logical terms, as the kernel does (active-low swaps them).
    const bool logical_rising = level != ((l.flags & GPIO_V2_LINE_FLAG_ACTIVE_LOW) != 0);
    const std::uint64_t want = logical_rising ? GPIO_V2_LINE_FLAG_EDGE_RISING : GPIO_V2_LINE_FLAG_EDGE_FALLING;
    if (l.flags & want) send_line_event(*l.owner, l.index, logical_rising, tick);
  }
}

void Board::send_line_event(Handle& h, unsigned index, bool rising, Tick tick) {
  GpioDev& g = *gpios_[h.dev];
  const unsigned off = h.offsets[index];
  // The host's clock at the edge's tick (the kernel stamps the edge when it happens).
  std::int64_t ts = time_.host_ns_of(tick);
  if (g.lines[off].flags & GPIO_V2_LINE_FLAG_EVENT_CLOCK_REALTIME) ts += time_.realtime_offset_ns();
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
  if (n < 0 && ++h.dropped == 1)
    log_.line(g.name + ": " + g.lines[off].name + ": event queue full, edge events dropped (the host does not read them)");
}

void Board::set_message_observer(MessageObserver observer) {
  std::lock_guard lock(m_);
  observer_ = std::move(observer);
}

// ---------------------------------------------------------------- the physical world

std::string Board::chain_summary(std::size_t chain) const {
  const ChainDev& c = *chains_.at(chain);
  std::ostringstream o;
  o << c.config.path << ": " << c.chain.size() << " chip" << (c.chain.size() == 1 ? "" : "s") << " (";
  for (std::size_t k = 0; k < c.config.chips.size(); ++k) o << (k ? "," : "") << c.config.chips[k]->name;
  o << ")";
  if (c.gpio >= 0) o << ", /dev/" << gpios_[static_cast<std::size_t>(c.gpio)]->name;
  return o.str();
}

int Board::find_chain(const std::string& name) const {
  for (std::size_t i = 0; i < chains_.size(); ++i) {
    const ChainDev& c = *chains_[i];
    const std::string short_name = std::to_string(c.config.bus) + "." + std::to_string(c.config.cs);
    if (name == c.name || name == c.config.path || name == short_name) return static_cast<int>(i);
    if (c.gpio >= 0 && name == gpios_[static_cast<std::size_t>(c.gpio)]->name) return static_cast<int>(i);
  }
  return -1;
}

void Board::with_chain(std::size_t chain, const std::function<void(Chain&)>& f) {
  std::lock_guard lock(m_);
  ChainDev& c = *chains_.at(chain);
  catch_up(c);
  f(c.chain);
  emit_changes(c, c.chain.now());
  wake_pump();
}

std::size_t Board::spidev_node(std::size_t chain) const {
  for (std::size_t i = 0; i < nodes_.size(); ++i)
    if (nodes_[i].type == DeviceNode::Type::spidev && node_target_[i] == static_cast<int>(chain)) return i;
  return nodes_.size();
}

std::size_t Board::chip_count(std::size_t chain) const { return chains_.at(chain)->chain.size(); }

bool Board::drive_pin(std::size_t chain, std::size_t chip, Pin pin, bool level) {
  std::lock_guard lock(m_);
  if (chain >= chains_.size() || pin_is_chip_output(pin)) return false;
  ChainDev& c = *chains_[chain];
  if (chip >= c.chain.size()) return false;
  catch_up(c);
  if (c.gpio < 0) {
    apply_input(c, chip, pin, level);
    return true;
  }
  GpioDev& g = *gpios_[static_cast<std::size_t>(c.gpio)];
  const unsigned off = line_offset(chip, pin);
  if (g.lines[off].owner && (g.lines[off].flags & GPIO_V2_LINE_FLAG_OUTPUT))
    log_.line(g.name + ": " + g.lines[off].name + " is driven by a host program; the physical world overrides it");
  set_chip_input(g, off, level);
  emit_changes(c, c.chain.now());
  wake_pump();
  return true;
}

bool Board::pin_level(std::size_t chain, std::size_t chip, Pin pin) {
  std::lock_guard lock(m_);
  ChainDev& c = *chains_.at(chain);
  catch_up(c);
  if (c.gpio >= 0) return physical_level(*gpios_[static_cast<std::size_t>(c.gpio)], line_offset(chip, pin));
  const Chip& ch = c.chain.chip(chip);
  if (pin == Pin::BUSY) return ch.busy_sync_pin();
  if (pin == Pin::FLAG) return ch.flag_pin();
  if (pin == Pin::SW) return ch.sw_pin();
  return pin == Pin::STBY_RST ? ch.spi_enabled() : false;
}

bool Board::advance(Tick ticks) { return time_.is_virtual() && advance_to(time_.now() + ticks); }

bool Board::advance_to(Tick tick) {
  if (!time_.is_virtual()) return false;
  std::lock_guard lock(m_);
  const Tick target = time_.set_now(tick);
  for (auto& c : chains_) {
    if (c->chain.now() < target) advance_chain(*c, target);
    emit_changes(*c, c->chain.now());
  }
  return true;
}

Tick Board::next_edge_tick() {
  std::lock_guard lock(m_);
  Tick best = kNever;
  for (auto& c : chains_) {
    catch_up(*c);
    best = std::min(best, predict_next_edge(*c));
  }
  return best;
}

Tick Board::now(std::size_t chain) {
  std::lock_guard lock(m_);
  ChainDev& c = *chains_.at(chain);
  catch_up(c);
  return c.chain.now();
}

std::string Board::describe_handles() {
  std::lock_guard lock(m_);
  std::ostringstream o;
  for (auto& c : chains_) o << c->name << ": " << c->users << " open, mode " << (c->spi.mode & 3) << ", "
                            << c->spi.speed_hz << " Hz, " << unsigned{c->spi.bits_per_word} << " bits/word"
                            << ((c->spi.mode & SPI_LSB_FIRST) ? ", LSB first" : "") << (c->chain.selected() ? ", CS held low" : "") << "\n";
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
