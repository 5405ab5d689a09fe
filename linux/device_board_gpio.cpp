// DeviceBoard: the gpiochip character device (v1 and v2 uAPI ioctls), after drivers/gpio/gpiolib-cdev.c.
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "linux/device_board_internal.hpp"

namespace l6470emu {
namespace {

template <typename T>
T load(std::span<const std::uint8_t> arg) {
  T v{};
  if (!arg.empty()) std::memcpy(&v, arg.data(), std::min(sizeof v, arg.size()));  // an empty argument may be null
  return v;
}

template <typename T>
void store(std::span<std::uint8_t> arg, const T& v) {
  if (!arg.empty()) std::memcpy(arg.data(), &v, std::min(sizeof v, arg.size()));
}

void copy_name(char (&dst)[GPIO_MAX_NAME_SIZE], const std::string& s) {
  std::memset(dst, 0, sizeof dst);
  std::memcpy(dst, s.data(), std::min(s.size(), sizeof dst - 1));
}

bool any_nonzero(const void* p, std::size_t n) {
  const auto* b = static_cast<const std::uint8_t*>(p);
  return std::any_of(b, b + n, [](std::uint8_t x) { return x != 0; });
}

}  // namespace

void DeviceBoard::fill_v2_info(GpioDev& g, unsigned offset, void* out) {
  auto* info = static_cast<gpio_v2_line_info*>(out);
  const LineDev& l = g.lines[offset];
  std::memset(info, 0, sizeof *info);
  copy_name(info->name, l.name);
  info->offset = offset;
  std::uint64_t flags = l.flags & (GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_OUTPUT | GPIO_V2_LINE_FLAG_ACTIVE_LOW |
                                   GPIO_V2_LINE_FLAG_OPEN_DRAIN | GPIO_V2_LINE_FLAG_OPEN_SOURCE |
                                   GPIO_V2_LINE_FLAG_BIAS_PULL_UP | GPIO_V2_LINE_FLAG_BIAS_PULL_DOWN |
                                   GPIO_V2_LINE_FLAG_BIAS_DISABLED);
  if (l.owner) {
    flags |= GPIO_V2_LINE_FLAG_USED;
    flags |= l.flags & (kV2EdgeFlags | GPIO_V2_LINE_FLAG_EVENT_CLOCK_REALTIME);
    copy_name(info->consumer, l.owner->consumer.empty() ? std::string("?") : l.owner->consumer);
  }
  info->flags = flags;
  if (l.owner && l.debounce_us) {
    info->num_attrs = 1;
    info->attrs[0].id = GPIO_V2_LINE_ATTR_ID_DEBOUNCE;
    info->attrs[0].debounce_period_us = l.debounce_us;
  }
}

void DeviceBoard::notify_lineinfo(GpioDev& g, unsigned offset, std::uint32_t event_type) {
  for (auto& [id, h] : handles_) {
    if (h->kind != HandleKind::gpiochip || gpios_[h->dev].get() != &g || offset >= h->watched.size() ||
        !h->watched[offset])
      continue;
    gpio_v2_line_info info{};
    fill_v2_info(g, offset, &info);
    const std::uint64_t ts = static_cast<std::uint64_t>(time().host_ns_of(time().now()));
    if (h->watch_abi == 1) {
      gpioline_info_changed c{};
      c.info.line_offset = offset;
      c.info.flags = v2_info_flags_to_v1(info.flags);
      std::memcpy(c.info.name, info.name, sizeof c.info.name);
      std::memcpy(c.info.consumer, info.consumer, sizeof c.info.consumer);
      c.timestamp = ts;
      c.event_type = event_type;
      send(h->fd, &c, sizeof c, MSG_DONTWAIT | MSG_NOSIGNAL);
    } else {
      gpio_v2_line_info_changed c{};
      c.info = info;
      c.timestamp_ns = ts;
      c.event_type = event_type;
      send(h->fd, &c, sizeof c, MSG_DONTWAIT | MSG_NOSIGNAL);
    }
  }
}

long DeviceBoard::gpiochip_ioctl(Handle& h, unsigned long cmd, std::span<std::uint8_t> arg, NewFile* created) {
  GpioDev& g = *gpios_[h.dev];
  const unsigned nlines = static_cast<unsigned>(g.lines.size());
  board_.catch_up(g.chain);

  switch (cmd) {
    case GPIO_GET_CHIPINFO_IOCTL: {
      gpiochip_info info{};
      copy_name(info.name, g.name);
      copy_name(info.label, g.label);
      info.lines = nlines;
      store(arg, info);
      return 0;
    }
    case GPIO_GET_LINEINFO_IOCTL:
    case GPIO_GET_LINEINFO_WATCH_IOCTL: {
      auto in = load<gpioline_info>(arg);
      if (in.line_offset >= nlines) return -EINVAL;
      if (cmd == GPIO_GET_LINEINFO_WATCH_IOCTL) {
        if (h.watch_abi == 2) return -EPERM;
        h.watch_abi = 1;
        if (h.watched[in.line_offset]) return -EBUSY;
        h.watched[in.line_offset] = true;
      }
      gpio_v2_line_info v2{};
      fill_v2_info(g, in.line_offset, &v2);
      gpioline_info out{};
      out.line_offset = in.line_offset;
      out.flags = v2_info_flags_to_v1(v2.flags);
      std::memcpy(out.name, v2.name, sizeof out.name);
      std::memcpy(out.consumer, v2.consumer, sizeof out.consumer);
      store(arg, out);
      return 0;
    }
    case GPIO_GET_LINEINFO_UNWATCH_IOCTL: {
      const auto offset = load<std::uint32_t>(arg);
      if (offset >= nlines) return -EINVAL;
      if (!h.watched[offset]) return -EBUSY;
      h.watched[offset] = false;
      return 0;
    }
    case GPIO_V2_GET_LINEINFO_IOCTL:
    case GPIO_V2_GET_LINEINFO_WATCH_IOCTL: {
      auto in = load<gpio_v2_line_info>(arg);
      if (any_nonzero(in.padding, sizeof in.padding)) return -EINVAL;
      if (in.offset >= nlines) return -EINVAL;
      if (cmd == GPIO_V2_GET_LINEINFO_WATCH_IOCTL) {
        if (h.watch_abi == 1) return -EPERM;
        h.watch_abi = 2;
        if (h.watched[in.offset]) return -EBUSY;
        h.watched[in.offset] = true;
      }
      gpio_v2_line_info out{};
      fill_v2_info(g, in.offset, &out);
      store(arg, out);
      return 0;
    }
    case GPIO_GET_LINEHANDLE_IOCTL: {
      auto req = load<gpiohandle_request>(arg);
      if (req.lines == 0 || req.lines > GPIOHANDLES_MAX) return -EINVAL;
      if (const int r = validate_v1_handle_flags(req.flags)) return r;
      std::vector<unsigned> offsets(req.lineoffsets, req.lineoffsets + req.lines);
      std::vector<std::uint64_t> flags(req.lines, v1_handle_flags_to_v2(req.flags));
      std::vector<int> values(req.lines, -1);
      if (req.flags & GPIOHANDLE_REQUEST_OUTPUT)
        for (unsigned i = 0; i < req.lines; ++i) values[i] = req.default_values[i] ? 1 : 0;
      char label[sizeof req.consumer_label + 1] = {};
      std::memcpy(label, req.consumer_label, sizeof req.consumer_label);
      const long r = request_lines(h, HandleKind::line_handle_v1, offsets, flags, values, label, 0,
                                   std::vector<std::uint32_t>(req.lines, 0), created);
      if (r < 0) return r;
      req.fd = created->fd;
      store(arg, req);
      return 0;
    }
    case GPIO_GET_LINEEVENT_IOCTL: {
      auto req = load<gpioevent_request>(arg);
      if (req.lineoffset >= nlines) return -EINVAL;
      if (const int r = validate_v1_event_flags(req.handleflags, req.eventflags)) return r;
      char label[sizeof req.consumer_label + 1] = {};
      std::memcpy(label, req.consumer_label, sizeof req.consumer_label);
      const long r = request_lines(h, HandleKind::line_event_v1, {req.lineoffset},
                                   {v1_event_flags_to_v2(req.handleflags, req.eventflags)}, {-1}, label, 16, {0}, created);
      if (r < 0) return r;
      req.fd = created->fd;
      store(arg, req);
      return 0;
    }
    case GPIO_V2_GET_LINE_IOCTL: {
      auto req = load<gpio_v2_line_request>(arg);
      if (req.num_lines == 0 || req.num_lines > GPIO_V2_LINES_MAX) return -EINVAL;
      if (any_nonzero(req.padding, sizeof req.padding)) return -EINVAL;
      if (const int r = validate_v2_config(req.config, req.num_lines)) return r;
      std::vector<unsigned> offsets(req.offsets, req.offsets + req.num_lines);
      std::vector<std::uint64_t> flags(req.num_lines);
      std::vector<int> values(req.num_lines, -1);
      std::vector<std::uint32_t> debounce(req.num_lines);
      for (unsigned i = 0; i < req.num_lines; ++i) {
        flags[i] = v2_config_flags(req.config, i);
        if (flags[i] & GPIO_V2_LINE_FLAG_EVENT_CLOCK_HTE) return -EOPNOTSUPP;  // no hardware timestamp engine
        debounce[i] = v2_config_debounce_us(req.config, i);
        bool v = false;
        if (flags[i] & GPIO_V2_LINE_FLAG_OUTPUT) values[i] = v2_config_output_value(req.config, i, v) && v ? 1 : 0;
      }
      char label[sizeof req.consumer + 1] = {};
      std::memcpy(label, req.consumer, sizeof req.consumer);
      const std::uint32_t ebs = req.event_buffer_size ? req.event_buffer_size : req.num_lines * 16;
      const long r = request_lines(h, HandleKind::line_request_v2, offsets, flags, values, label, ebs, debounce, created);
      if (r < 0) return r;
      req.fd = created->fd;
      store(arg, req);
      return 0;
    }
    default:
      return -EINVAL;
  }
}

long DeviceBoard::request_lines(Handle& chip, HandleKind kind, const std::vector<unsigned>& offsets,
                                const std::vector<std::uint64_t>& flags, const std::vector<int>& values,
                                const char* consumer, std::uint32_t /*event_buffer_size*/,
                                const std::vector<std::uint32_t>& debounce, NewFile* created) {
  GpioDev& g = *gpios_[chip.dev];
  for (unsigned off : offsets)
    if (off >= g.lines.size()) return -EINVAL;
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    if (g.lines[offsets[i]].owner) return -EBUSY;
    for (std::size_t j = 0; j < i; ++j)
      if (offsets[j] == offsets[i]) return -EBUSY;
  }
  if (const long r = refuse_spi_line_edges(g, offsets, flags)) return r;
  if (!created) return -EINVAL;
  std::unique_ptr<Handle> h;
  NewFile f = make_handle(kind, chip.dev, /*cloexec=*/true, h);  // anon_inode_getfile(O_RDONLY | O_CLOEXEC)
  if (f.result < 0) return f.result;
  Handle& r = *h;
  handles_.emplace(r.id, std::move(h));
  r.offsets = offsets;
  r.consumer = consumer ? consumer : "";
  r.line_seqno.assign(offsets.size(), 0);
  bool edges = false;
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    LineDev& l = g.lines[offsets[i]];
    l.owner = &r;
    l.index = static_cast<unsigned>(i);
    std::uint64_t fl = flags[i];
    if (!(fl & (GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_OUTPUT)))  // v1 "as is": keep the direction
      fl |= l.flags & (GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_OUTPUT);
    l.flags = fl;
    l.debounce_us = debounce[i];
    if ((fl & GPIO_V2_LINE_FLAG_OUTPUT) && !g.layout.spi_line(offsets[i]) && pin_is_chip_output(g.layout.pin_of(offsets[i])))
      log_.line(g.name + ": line " + l.name + " requested as an output by \"" + r.consumer +
                "\", but the chip drives it (the host reads back its own value)");
    edges = edges || (fl & kV2EdgeFlags);
  }
  set_requested_values(g, offsets, values);
  for (unsigned off : offsets)
    if (g.lines[off].flags & kV2EdgeFlags) watch_line(g, off, true);
  board_.report_changes(g.chain);  // outputs set at request time may have edges for others
  for (unsigned off : offsets) notify_lineinfo(g, off, GPIO_V2_LINE_CHANGED_REQUESTED);
  *created = f;
  if (edges && !time().is_virtual() && !pump_running_) {
    pump_stop_ = false;
    pump_running_ = true;
    pump_ = std::thread([this] { pump_loop(); });
  }
  wake_pump();
  return 0;
}

long DeviceBoard::reconfigure_lines(Handle& h, const std::vector<std::uint64_t>& flags, const std::vector<int>& values,
                                    const std::vector<std::uint32_t>& debounce) {
  GpioDev& g = *gpios_[h.dev];
  if (const long r = refuse_spi_line_edges(g, h.offsets, flags)) return r;
  bool edges = false;
  for (std::size_t i = 0; i < h.offsets.size(); ++i) {
    LineDev& l = g.lines[h.offsets[i]];
    std::uint64_t fl = flags[i];
    if (!(fl & (GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_OUTPUT)))
      fl |= l.flags & (GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_OUTPUT);
    l.flags = fl;
    l.debounce_us = debounce[i];
  }
  set_requested_values(g, h.offsets, values);
  for (std::size_t i = 0; i < h.offsets.size(); ++i) {
    const std::uint64_t fl = g.lines[h.offsets[i]].flags;
    watch_line(g, h.offsets[i], (fl & kV2EdgeFlags) != 0);  // a watch starts from the level now
    edges = edges || (fl & kV2EdgeFlags);
  }
  board_.report_changes(g.chain);
  for (unsigned off : h.offsets) notify_lineinfo(g, off, GPIO_V2_LINE_CHANGED_CONFIG);
  if (edges && !time().is_virtual() && !pump_running_) {
    pump_stop_ = false;
    pump_running_ = true;
    pump_ = std::thread([this] { pump_loop(); });
  }
  wake_pump();
  return 0;
}

long DeviceBoard::refuse_spi_line_edges(GpioDev& g, const std::vector<unsigned>& offsets,
                                        const std::vector<std::uint64_t>& flags) {
  for (std::size_t i = 0; i < offsets.size(); ++i)
    if (g.layout.spi_line(offsets[i]) && (flags[i] & kV2EdgeFlags)) {
      log_.line(g.name + ": edge events on " + g.lines[offsets[i]].name +
                " are not emulated (the SPI lines are read and set only): the request is refused (EOPNOTSUPP)");
      return -EOPNOTSUPP;
    }
  return 0;
}

void DeviceBoard::set_requested_values(GpioDev& g, const std::vector<unsigned>& offsets, const std::vector<int>& values) {
  // A request's output values, in offset order as a set of values is (apply_values).
  std::vector<unsigned> order(offsets.size());
  for (unsigned i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](unsigned a, unsigned b) { return offsets[a] < offsets[b]; });
  for (const unsigned i : order) {
    const unsigned off = offsets[i];
    const std::uint64_t fl = g.lines[off].flags;
    if (!(fl & GPIO_V2_LINE_FLAG_OUTPUT) || values[i] < 0) continue;
    const bool level = (values[i] != 0) != ((fl & GPIO_V2_LINE_FLAG_ACTIVE_LOW) != 0);
    if (const auto line = g.layout.spi_line(off))
      set_spi_line(g, *line, level, /*at_request=*/true);
    else
      set_chip_input(g, off, level);
  }
}

Tick DeviceBoard::apply_values(Handle& h, const std::vector<unsigned>& indices, const std::vector<bool>& levels) {
  // One call's values reach the board one line at a time, in offset order (CS, SCK, MOSI): a
  // rising SCK set together with MOSI samples the MOSI from before the call, as a data line
  // changing at a clock edge breaks the chip's hold time. Data goes out a call before its clock.
  GpioDev& g = *gpios_[h.dev];
  std::vector<unsigned> order(indices.size());
  for (unsigned k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(),
            [&](unsigned a, unsigned b) { return h.offsets[indices[a]] < h.offsets[indices[b]]; });
  bool spi = false;
  for (const unsigned k : order) {
    const unsigned off = h.offsets[indices[k]];
    const auto line = g.layout.spi_line(off);
    spi = spi || (line && *line != SpiLine::miso);
    set_chip_input(g, off, levels[k]);
  }
  board_.report_changes(g.chain);
  wake_pump();
  return spi ? time().now() + kSpiLineSetTicks : 0;
}

bool DeviceBoard::logical_value(Handle& h, unsigned index) {
  GpioDev& g = *gpios_[h.dev];
  const unsigned off = h.offsets[index];
  if (!g.layout.spi_line(off))
    board_.note_output_read(g.chain, g.layout.chip_of(off), g.layout.pin_of(off));  // the host looks (BUSY, FLAG)
  return physical_level(g, off) != ((g.lines[off].flags & GPIO_V2_LINE_FLAG_ACTIVE_LOW) != 0);
}

long DeviceBoard::line_ioctl(Handle& h, unsigned long cmd, std::span<std::uint8_t> arg, Tick& lasts_to) {
  GpioDev& g = *gpios_[h.dev];
  board_.catch_up(g.chain);
  const unsigned n = static_cast<unsigned>(h.offsets.size());

  if (h.kind == HandleKind::line_handle_v1 || h.kind == HandleKind::line_event_v1) {
    if (cmd == GPIOHANDLE_GET_LINE_VALUES_IOCTL) {
      gpiohandle_data d{};
      for (unsigned i = 0; i < n; ++i) d.values[i] = logical_value(h, i) ? 1 : 0;
      store(arg, d);
      return 0;
    }
    if (h.kind == HandleKind::line_event_v1) return -EINVAL;
    if (cmd == GPIOHANDLE_SET_LINE_VALUES_IOCTL) {
      if (!(g.lines[h.offsets[0]].flags & GPIO_V2_LINE_FLAG_OUTPUT)) return -EPERM;
      const auto d = load<gpiohandle_data>(arg);
      std::vector<unsigned> indices(n);
      std::vector<bool> levels(n);
      for (unsigned i = 0; i < n; ++i) {
        const LineDev& l = g.lines[h.offsets[i]];
        indices[i] = i;
        levels[i] = (d.values[i] != 0) != ((l.flags & GPIO_V2_LINE_FLAG_ACTIVE_LOW) != 0);
      }
      lasts_to = apply_values(h, indices, levels);
      return 0;
    }
    if (cmd == GPIOHANDLE_SET_CONFIG_IOCTL) {
      const auto cfg = load<gpiohandle_config>(arg);
      if (any_nonzero(cfg.padding, sizeof cfg.padding)) return -EINVAL;
      if (const int r = validate_v1_handle_flags(cfg.flags)) return r;
      std::vector<std::uint64_t> flags(n, v1_handle_flags_to_v2(cfg.flags));
      std::vector<int> values(n, -1);
      if (cfg.flags & GPIOHANDLE_REQUEST_OUTPUT)
        for (unsigned i = 0; i < n; ++i) values[i] = cfg.default_values[i] ? 1 : 0;
      return reconfigure_lines(h, flags, values, std::vector<std::uint32_t>(n, 0));
    }
    return -EINVAL;
  }

  // v2 line request
  switch (cmd) {
    case GPIO_V2_LINE_GET_VALUES_IOCTL: {
      auto lv = load<gpio_v2_line_values>(arg);
      if (lv.mask == 0) return -EINVAL;
      std::uint64_t bits = 0;
      for (unsigned i = 0; i < n; ++i)
        if ((lv.mask >> i) & 1u && logical_value(h, i)) bits |= std::uint64_t{1} << i;
      lv.bits = bits;
      store(arg, lv);
      return 0;
    }
    case GPIO_V2_LINE_SET_VALUES_IOCTL: {
      const auto lv = load<gpio_v2_line_values>(arg);
      if (lv.mask == 0) return -EINVAL;
      for (unsigned i = 0; i < n; ++i)
        if ((lv.mask >> i) & 1u && !(g.lines[h.offsets[i]].flags & GPIO_V2_LINE_FLAG_OUTPUT)) return -EPERM;
      std::vector<unsigned> indices;
      std::vector<bool> levels;
      for (unsigned i = 0; i < n; ++i) {
        if (!((lv.mask >> i) & 1u)) continue;
        const LineDev& l = g.lines[h.offsets[i]];
        indices.push_back(i);
        levels.push_back((((lv.bits >> i) & 1u) != 0) != ((l.flags & GPIO_V2_LINE_FLAG_ACTIVE_LOW) != 0));
      }
      lasts_to = apply_values(h, indices, levels);
      return 0;
    }
    case GPIO_V2_LINE_SET_CONFIG_IOCTL: {
      const auto cfg = load<gpio_v2_line_config>(arg);
      if (const int r = validate_v2_config(cfg, n)) return r;
      std::vector<std::uint64_t> flags(n);
      std::vector<int> values(n, -1);
      std::vector<std::uint32_t> debounce(n);
      for (unsigned i = 0; i < n; ++i) {
        flags[i] = v2_config_flags(cfg, i);
        if (flags[i] & GPIO_V2_LINE_FLAG_EVENT_CLOCK_HTE) return -EOPNOTSUPP;
        debounce[i] = v2_config_debounce_us(cfg, i);
        bool v = false;
        if (flags[i] & GPIO_V2_LINE_FLAG_OUTPUT) values[i] = v2_config_output_value(cfg, i, v) && v ? 1 : 0;
      }
      return reconfigure_lines(h, flags, values, debounce);
    }
    default:
      return -EINVAL;
  }
}

}  // namespace l6470emu
