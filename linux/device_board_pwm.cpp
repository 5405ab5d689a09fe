// The kernel's pwm sysfs class on the chips' STCK (DeviceBoard::pwm_write): one pwmchip per chain,
// a channel per chip, an enabled channel a pulse train in the Board (board/pulse_train.hpp), which
// costs nothing per pulse while no edge has to be seen one by one.
#include <errno.h>

#include "linux/device_board.hpp"
#include "linux/device_board_internal.hpp"

namespace l6470emu {
namespace {

// The count clock of the trains: 1 GHz, so that period and duty are whole counts in nanoseconds.
constexpr std::uint64_t kPwmClockHz = 1'000'000'000;

// The pin's high time in a period of `s` (the active part, or the inactive one when inversed).
std::uint64_t high_ns(const PwmSettings& s) { return s.inversed ? s.period_ns - s.duty_ns : s.duty_ns; }

}  // namespace

std::size_t DeviceBoard::pwm_channels(std::size_t chain) const {
  return chain < board_.chain_count() ? board_.chip_count(chain) : 0;
}

DeviceBoard::PwmChannel* DeviceBoard::pwm_channel(std::size_t chain, std::size_t chip) {
  if (chain >= board_.chain_count() || chip >= board_.chip_count(chain)) return nullptr;
  if (pwm_.size() != board_.chain_count()) pwm_.resize(board_.chain_count());
  if (pwm_[chain].size() != board_.chip_count(chain)) pwm_[chain].resize(board_.chip_count(chain));
  return &pwm_[chain][chip];
}

void DeviceBoard::set_stck_level(std::size_t chain, std::size_t chip, bool level) {
  if (!board_.stop_pulse_train(chain, chip, Pin::STCK, level)) board_.set_input(chain, chip, Pin::STCK, level);
}

void DeviceBoard::apply_pwm(std::size_t chain, std::size_t chip, PwmChannel& ch, const PwmSettings& next) {
  board_.catch_up(chain);
  const Tick now = board_.now(chain);
  const std::uint64_t high = high_ns(next);
  if (!next.enabled || high == 0 || high == next.period_ns) {
    // Off, or a steady level (duty 0 or a whole period): now.
    set_stck_level(chain, chip, next.enabled && high != 0);
    ch.train_on = false;
  } else {
    PulseTrain t;
    t.clock_hz = kPwmClockHz;
    t.period_counts = next.period_ns;
    t.high_counts = high;
    if (!ch.train_on) set_stck_level(chain, chip, false);
    bool started = false;
    // On the wall clock the board's time moves on while this runs: a start in the past is
    // refused, so the train starts a microsecond on (and is tried again with the time then).
    const Tick lead = board_.time().is_virtual() ? 0 : kTicksPerMicrosecond;
    for (int attempt = 0; attempt < 4 && !started; ++attempt) {
      const Tick at = attempt == 0 ? now : board_.now(chain);
      t.start = at + lead;
      // Running: the new period and duty from the pin's next rising edge on.
      if (ch.train_on && ch.settings.enabled) t.start = ch.train.rise_tick(ch.train.rises_through(at + lead));
      started = board_.drive_pulse_train(chain, chip, Pin::STCK, t);
    }
    if (started) {
      ch.train = t;
      ch.train_on = true;
    } else {
      log_.line("pwmchip" + std::to_string(chain) + "/pwm" + std::to_string(chip) + ": no pulse train started");
    }
  }
  ch.settings = next;
  board_.report_changes(chain);
  wake_pump();
}

long DeviceBoard::pwm_write(std::size_t chain, int channel, PwmAttr attr, std::string_view text) {
  std::lock_guard lock(m_);
  if (chain >= board_.chain_count()) return -ENODEV;
  const long taken = static_cast<long>(text.size());
  if (attr == PwmAttr::export_channel || attr == PwmAttr::unexport_channel) {
    std::uint64_t k = 0;
    // kstrtouint: a number over 32 bits is -ERANGE.
    if (const long r = parse_kernel_u64(text, k); r < 0) return r;
    if (k > 0xFFFF'FFFFu) return -ERANGE;
    PwmChannel* ch = pwm_channel(chain, static_cast<std::size_t>(k));
    if (!ch) return -ENODEV;
    if (attr == PwmAttr::export_channel) {
      if (ch->exported) return -EBUSY;
      ch->exported = true;
      return taken;
    }
    if (!ch->exported) return -ENODEV;
    // Unexport frees the channel: its output stops and its settings are forgotten.
    apply_pwm(chain, static_cast<std::size_t>(k), *ch, PwmSettings{});
    *ch = PwmChannel{};
    return taken;
  }
  if (attr == PwmAttr::npwm) return -EACCES;
  if (channel < 0) return -ENODEV;
  PwmChannel* ch = pwm_channel(chain, static_cast<std::size_t>(channel));
  if (!ch) return -ENODEV;
  if (!ch->exported) return -ENOENT;
  PwmSettings next;
  if (const long r = pwm_settings_after(ch->settings, attr, text, next); r < 0) return r;
  apply_pwm(chain, static_cast<std::size_t>(channel), *ch, next);
  return taken;
}

long DeviceBoard::pwm_read(std::size_t chain, int channel, PwmAttr attr, std::string& out) {
  std::lock_guard lock(m_);
  if (chain >= board_.chain_count()) return -ENODEV;
  if (!pwm_attr_readable(attr)) return -EACCES;
  if (attr == PwmAttr::npwm) {
    out = std::to_string(board_.chip_count(chain)) + "\n";
    return 0;
  }
  if (channel < 0) return -ENODEV;
  PwmChannel* ch = pwm_channel(chain, static_cast<std::size_t>(channel));
  if (!ch) return -ENODEV;
  if (!ch->exported) return -ENOENT;
  out = pwm_attr_text(ch->settings, attr);
  return 0;
}

bool DeviceBoard::pwm_exported(std::size_t chain, std::size_t channel) {
  std::lock_guard lock(m_);
  const PwmChannel* ch = pwm_channel(chain, channel);
  return ch && ch->exported;
}

std::uint64_t DeviceBoard::pwm_rises(std::size_t chain, std::size_t channel) {
  std::lock_guard lock(m_);
  if (chain >= board_.chain_count()) return 0;
  return board_.pulse_train_rises(chain, channel, Pin::STCK);
}

Board::PulseTrainCounts DeviceBoard::pulse_train_counts() {
  std::lock_guard lock(m_);
  return board_.pulse_train_counts();
}

}  // namespace l6470emu
