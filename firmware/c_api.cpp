// The plain C API (firmware/firmware.h) over the FirmwareRuntime: names to pin keys, each call
// charged as one HAL call.
#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "firmware/firmware.h"
#include "firmware/runtime.hpp"

using l6470emu::FirmwareFront;
using l6470emu::FirmwareRuntime;

namespace {

std::string g_error;

FirmwareRuntime& rt() { return l6470emu::firmware_runtime(FirmwareFront::c_api); }

bool valid_pin(int pin) { return pin >= 0 && pin < FirmwareRuntime::kPinKeys; }

struct EdgeCallback {
  l6470emu_fw_edge_fn fn = nullptr;
  void* arg = nullptr;
  int irq = -1;
  int level = 0;
};
std::vector<EdgeCallback> g_edges(FirmwareRuntime::kPinKeys);

/// Runs a C API call's body: a C++ exception (an allocation that failed, a bug) never crosses
/// into the C caller; it becomes the call's error value, its text in l6470emu_fw_error().
template <typename R, typename F>
R guarded(R on_error, F&& body) noexcept {
  try {
    return body();
  } catch (const std::exception& e) {
    g_error = e.what();
  } catch (...) {
    g_error = "unexpected error";
  }
  return on_error;
}
template <typename F>
void guarded(F&& body) noexcept {
  try {
    body();
  } catch (const std::exception& e) {
    g_error = e.what();
  } catch (...) {
    g_error = "unexpected error";
  }
}

}  // namespace

extern "C" {

int l6470emu_fw_open(const char* description) {
  return guarded(-1, [&]() -> int {
    std::string error;
    if (!l6470emu::open_firmware_runtime(description, FirmwareFront::c_api, error)) {
      g_error = error;
      return -1;
    }
    g_error.clear();
    return 0;
  });
}

const char* l6470emu_fw_error(void) { return g_error.c_str(); }

void l6470emu_fw_close(void) {
  guarded([&] {
    if (FirmwareRuntime* r = l6470emu::existing_firmware_runtime()) r->finish();
  });
}

int l6470emu_fw_pin(const char* name) {
  return guarded(-1, [&]() -> int {
    if (!name) return -1;
    const auto pin = l6470emu::parse_mcu_pin(name);
    return pin ? FirmwareRuntime::key_of(*pin) : -1;
  });
}

int l6470emu_fw_pin_mode(int pin, int mode) {
  return guarded(-1, [&]() -> int {
    FirmwareRuntime& r = rt();
    r.call();
    if (!valid_pin(pin) || mode < L6470EMU_FW_INPUT || mode > L6470EMU_FW_OUTPUT_OPEN_DRAIN) return -1;
    r.set_pin_mode(pin, static_cast<l6470emu::McuPinMode>(mode));
    return 0;
  });
}

int l6470emu_fw_pin_write(int pin, int level) {
  return guarded(-1, [&]() -> int {
    FirmwareRuntime& r = rt();
    r.call();
    if (!valid_pin(pin)) return -1;
    r.write_pin(pin, level != 0);
    return 0;
  });
}

int l6470emu_fw_pin_read(int pin) {
  return guarded(-1, [&]() -> int {
    FirmwareRuntime& r = rt();
    r.call();
    if (!valid_pin(pin)) return -1;
    return r.read_pin(pin) ? 1 : 0;
  });
}

int l6470emu_fw_pin_wait(int pin, int level, uint64_t timeout_ns) {
  return guarded(-1, [&]() -> int {
    FirmwareRuntime& r = rt();
    r.call();
    if (!valid_pin(pin)) return -1;
    return r.wait_for_level(pin, level != 0, r.now() + timeout_ns / 250) ? 0 : 1;
  });
}

int l6470emu_fw_pin_on_edge(int pin, int edges, l6470emu_fw_edge_fn fn, void* arg) {
  return guarded(-1, [&]() -> int {
    FirmwareRuntime& r = rt();
    r.call();
    if (!valid_pin(pin) || edges < 0 || edges > L6470EMU_FW_EDGE_BOTH) return -1;
    EdgeCallback& cb = g_edges[static_cast<std::size_t>(pin)];
    if (edges == L6470EMU_FW_EDGE_NONE || !fn) {
      r.watch_pin(pin, 0, nullptr);
      if (cb.irq >= 0) r.set_irq_enabled(cb.irq, false);
      cb.fn = nullptr;
      return 0;
    }
    cb.fn = fn;
    cb.arg = arg;
    if (cb.irq < 0)
      cb.irq = r.add_irq([pin] {
        const EdgeCallback& c = g_edges[static_cast<std::size_t>(pin)];
        if (c.fn) c.fn(pin, c.level, c.arg);
      });
    r.set_irq_enabled(cb.irq, true);
    const int irq = cb.irq;
    r.watch_pin(pin, static_cast<unsigned>(edges), [&r, pin, irq](bool level) {
      g_edges[static_cast<std::size_t>(pin)].level = level ? 1 : 0;
      r.pend_irq(irq);
    });
    return 0;
  });
}

void l6470emu_fw_irq_disable(void) {
  guarded([&] {
    FirmwareRuntime& r = rt();
    r.call();
    r.disable_interrupts();
  });
}

void l6470emu_fw_irq_enable(void) {
  guarded([&] {
    FirmwareRuntime& r = rt();
    r.call();
    r.enable_interrupts();
  });
}

int l6470emu_fw_spi_bus(const char* name) {
  return guarded(-1, [&]() -> int {
    FirmwareRuntime& r = rt();
    r.call();
    if (!name) return r.controller_names().empty() ? -1 : 0;
    return r.controller(name);
  });
}

int l6470emu_fw_spi_transfer(int bus, int cs_pin, const struct l6470emu_fw_spi_config* config, const uint8_t* tx,
                             uint8_t* rx, size_t len) {
  return guarded(-1, [&]() -> int {
    FirmwareRuntime& r = rt();
    r.call();
    if (bus < 0 || bus >= static_cast<int>(r.controller_names().size())) return -1;
    if (cs_pin >= 0 && !valid_pin(cs_pin)) return -1;
    if (cs_pin < -1) return -1;
    l6470emu::BusSettings settings;
    settings.speed_hz = config && config->speed_hz ? config->speed_hz : 5'000'000;
    settings.mode = config ? config->mode : 0;
    settings.lsb_first = config && config->lsb_first;
    if (settings.mode > 3) return -1;
    if (cs_pin >= 0) {
      r.set_pin_mode(cs_pin, l6470emu::McuPinMode::output);
      r.write_pin(cs_pin, false);
      r.call();  // the chip select's set-up before the first clock
    }
    if (tx && rx) {
      r.transfer(bus, settings, std::span<const std::uint8_t>(tx, len), std::span<std::uint8_t>(rx, len));
    } else {
      // NULL buffers stand for zeros out or bytes dropped: a bounded scratch buffer at a time, not
      // one as long as the transfer (a length near SIZE_MAX ends at the run's time limit, not in
      // an allocation).
      std::array<std::uint8_t, 4096> zeros{}, sink{};
      for (std::size_t done = 0; done < len;) {
        const std::size_t n = std::min(len - done, zeros.size());
        r.transfer(bus, settings, std::span<const std::uint8_t>(tx ? tx + done : zeros.data(), n),
                   std::span<std::uint8_t>(rx ? rx + done : sink.data(), n));
        done += n;
      }
    }
    if (cs_pin >= 0) r.write_pin(cs_pin, true);
    return 0;
  });
}

uint64_t l6470emu_fw_now_ns(void) {
  return guarded(std::uint64_t{0}, [&]() -> uint64_t {
    FirmwareRuntime& r = rt();
    r.call();
    return r.now() * 250;
  });
}

void l6470emu_fw_sleep_ns(uint64_t ns) {
  guarded([&] {
    FirmwareRuntime& r = rt();
    r.call();
    // Rounded up to whole ticks, saturating: a sleep near UINT64_MAX ns is for ever, not none.
    const l6470emu::Tick ticks = ns / 250 + (ns % 250 != 0 ? 1 : 0);
    r.sleep_until(ticks > l6470emu::kNever - 1 - r.now() ? l6470emu::kNever - 1 : r.now() + ticks);
  });
}

void l6470emu_fw_call(void) {
  guarded([] { rt().call(); });
}

}  // extern "C"
