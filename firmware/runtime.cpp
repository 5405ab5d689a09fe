// FirmwareRuntime: time and its costs, the pins as the board wires them, edges turned into
// pending interrupts, delivery, SPI controllers, the end of a run.
#include "firmware/runtime.hpp"
#include "core/counted.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "board/coverage_file.hpp"
#include "board/environment_names.hpp"
#include "board/scenario_runner.hpp"
#include "daisychain/chip_numbering.hpp"
#include "firmware/run.hpp"

extern char** environ;  // POSIX's, declared here: <unistd.h> is not for the OS-free fronts

namespace l6470emu {

/// One microcontroller pin: how the program set it, what the board wires to it, who watches it.
struct FirmwareRuntime::Line {
  int key = 0;
  McuPinMode mode = McuPinMode::input;
  bool latch = false;             // the output latch (an AVR's PORT bit)
  int cs_chain = -1;              // the chain whose chip select it is
  std::vector<ChipRef> outputs;   // chip BUSY/FLAG on it (open drain: wired together)
  std::vector<ChipRef> inputs;    // chip SW/STCK/STBY_RST it drives
  std::vector<std::size_t> sck_chains, mosi_chains, miso_chains;  // SPI at the pins: the chains it is CK, SDI or SDO of
  std::uint64_t unselected_rising = 0;  // a CK line: rising edges while none of its chains was selected
  std::uint64_t unmapped_change = 0;    // a line the description does not map: unmapped_writes_ at its last change (0 none)
  int applied = -1;               // what it last drove onto the board: -1 unknown, 0 low, 1 high, 2 released
  unsigned edges = 0;
  std::function<void(bool)> on_edge;
  bool level_watch = false;
  bool watched_level = false;
  std::function<void(bool)> on_level;
  bool seen = true;               // the level the watch last saw
  bool board_watched = false;
};

namespace {

/// Virtual time reads no clock: the board's time starts at kVirtualMonotonicOrigin and moves
/// only when the runtime moves it, so every run is the same.
class FixedHostClock final : public HostClock {
 public:
  std::int64_t monotonic_ns() override { return kVirtualMonotonicOrigin; }
  std::int64_t realtime_ns() override { return kVirtualMonotonicOrigin; }
  void sleep_until(std::int64_t) override {}
};

/// A time as "12.5 s" (whole microseconds at most).
std::string short_seconds_text(Tick ticks) {
  const std::uint64_t us = ticks / kTicksPerMicrosecond;
  std::string frac = std::to_string(us % 1'000'000);
  frac.insert(0, 6 - frac.size(), '0');
  while (!frac.empty() && frac.back() == '0') frac.pop_back();
  return std::to_string(us / 1'000'000) + (frac.empty() ? "" : "." + frac) + " s";
}

std::string limit_text(Tick ticks) {
  const std::uint64_t ns = ticks * 250;
  if (ns % 1'000'000'000 == 0) return std::to_string(ns / 1'000'000'000) + "s";
  if (ns % 1'000'000 == 0) return std::to_string(ns / 1'000'000) + "ms";
  return std::to_string(ns / 1000) + "us";
}

/// The default wiring of chain 0 when a description names no pin (docs/firmware.md): an Uno's
/// D10 (SS) for CS, D2 and D3 (its two interrupt pins) for FLAG and BUSY, D6 for STBY_RST; for
/// the STM32 HAL the pins a Nucleo-64 brings to those Arduino header positions.
void apply_default_pins(BoardConfig& config, FirmwareFront front) {
  if (config.chains.empty()) return;
  for (const ChainConfig& c : config.chains)
    if (c.pins.any()) return;
  ChainPins& p = config.chains[0].pins;
  auto pin = [](const char* name) { return *parse_mcu_pin(name); };
  const bool stm32 = front == FirmwareFront::stm32_hal;
  p.cs = pin(stm32 ? "PB6" : "D10");
  p.chip[static_cast<unsigned>(Pin::FLAG)] = {pin(stm32 ? "PA10" : "D2")};
  p.chip[static_cast<unsigned>(Pin::BUSY)] = {pin(stm32 ? "PB3" : "D3")};
  p.chip[static_cast<unsigned>(Pin::STBY_RST)] = {pin(stm32 ? "PB10" : "D6")};
}

}  // namespace

FirmwareRuntime::FirmwareRuntime(const BoardConfig& config, FirmwareFront front, LineSink log,
                                 ArduinoBoard arduino_board)
    : front_(front), arduino_board_(arduino_board), config_(config), timing_(config.firmware), log_(std::move(log)), limit_ticks_(timing_.limit_ticks) {
  if (!config_.socket.empty())
    throw std::invalid_argument("socket= forwards to an l6470emu serve daemon; a firmware run has its board in itself");
  if (!config_.time.virtual_time && config_.time.scale != 1.0)
    throw std::invalid_argument("scale= is for wall time; a firmware run is always in virtual time");
  if (config_.chains.empty()) throw std::invalid_argument("the board description has no chain");
  config_.time.virtual_time = true;
  config_.time.idle_ns = 0;
  apply_default_pins(config_, front_);
  if (front_ == FirmwareFront::arduino) map_arduino_header(config_, arduino_board_);
  clock_ = std::make_unique<FixedHostClock>();
  board_ = std::make_unique<Board>(config_, log_, *clock_);
  board_->set_edge_sink([this](const PinEdge& e) { edges_.push_back(e); });
  wire(config_);
  timers_ = std::make_unique<FirmwareTimers>(*this);
}

FirmwareRuntime::~FirmwareRuntime() {
  finish();
  scenario_.reset();  // gives the board's sinks back before the board goes
}

// ---------------------------------------------------------------- wiring

FirmwareRuntime::Line* FirmwareRuntime::line(int key) {
  if (key < 0 || key >= kPinKeys || line_of_[static_cast<std::size_t>(key)] == 0) return nullptr;
  return lines_[static_cast<std::size_t>(line_of_[static_cast<std::size_t>(key)] - 1)].get();
}

const FirmwareRuntime::Line* FirmwareRuntime::line(int key) const {
  return const_cast<FirmwareRuntime*>(this)->line(key);
}

FirmwareRuntime::Line& FirmwareRuntime::make_line(int key) {
  if (Line* l = line(key)) return *l;
  auto l = std::make_unique<Line>();
  l->key = key;
  lines_.push_back(std::move(l));
  line_of_[static_cast<std::size_t>(key)] = static_cast<int>(lines_.size());
  return *lines_.back();
}

void FirmwareRuntime::wire(const BoardConfig& config) {
  chip_line_.resize(config.chains.size());
  tracked_.resize(config.chains.size());
  unmapped_at_select_.assign(config.chains.size(), 0);
  unclocked_frames_.assign(config.chains.size(), 0);
  for (std::size_t i = 0; i < config.chains.size(); ++i) {
    const ChainConfig& c = config.chains[i];
    const std::size_t n = c.chips.size();
    std::array<int, kPinsPerChip> none;
    none.fill(-1);
    chip_line_[i].assign(n, none);
    tracked_[i].assign(n, std::array<bool, kPinsPerChip>{true, true, true, true, true});
    const std::string name = board_->chain_name(i);
    if (c.pins.cs) {
      make_line(key_of(*c.pins.cs)).cs_chain = static_cast<int>(i);
    } else {
      log(name + ": no cs_pin= in the board description: nothing selects this chain");
    }
    if (c.pins.sck) make_line(key_of(*c.pins.sck)).sck_chains.push_back(i);
    if (c.pins.mosi) make_line(key_of(*c.pins.mosi)).mosi_chains.push_back(i);
    if (c.pins.miso) make_line(key_of(*c.pins.miso)).miso_chains.push_back(i);
    const ChipNumbering numbers(config.numbering, n);
    for (unsigned p = 0; p < kPinsPerChip; ++p) {
      const Pin pin = static_cast<Pin>(p);
      for (std::size_t k = 0; k < n; ++k) {
        const auto mcu = chip_mcu_pin(c.pins, pin, numbers.number_of(k));
        if (!mcu) continue;
        const int key = key_of(*mcu);
        chip_line_[i][k][p] = key;
        Line& l = make_line(key);
        (pin_is_chip_output(pin) ? l.outputs : l.inputs).push_back(ChipRef{i, k, pin});
      }
    }
  }
  // Pins the front has no name for.
  for (const int key : wired_pins()) {
    if (front_ == FirmwareFront::stm32_hal && key < 128)
      log("pin " + std::to_string(key) + " of the board description is an Arduino pin number: an STM32 HAL program "
          "names its pins PA0 to PK15 and cannot reach it");
    if (front_ == FirmwareFront::arduino && key >= 256)
      log("pin " + to_string(pin_of(key)) + " of the board description has no Arduino pin number (PA0 to PH15 have)");
  }
  // Controllers: a bus is named by the spi= of a chain on it, else after its number.
  std::vector<unsigned> buses;
  for (const ChainConfig& c : config.chains)
    if (std::find(buses.begin(), buses.end(), c.bus) == buses.end()) buses.push_back(c.bus);
  std::sort(buses.begin(), buses.end());
  for (const unsigned bus : buses) {
    Controller ctl;
    bool named = false;
    for (std::size_t i = 0; i < config.chains.size(); ++i) {
      if (config.chains[i].bus != bus) continue;
      ctl.chains.push_back(i);
      if (!config.chains[i].pins.spi.empty()) {
        ctl.name = config.chains[i].pins.spi;
        named = true;
      }
    }
    if (!named)
      ctl.name = front_ == FirmwareFront::stm32_hal ? "SPI" + std::to_string(bus + 1)
                 : bus == 0                         ? std::string("SPI")
                                                    : "SPI" + std::to_string(bus);
    for (const Controller& other : controllers_)
      if (other.name == ctl.name)
        throw std::invalid_argument("two buses are both controller " + ctl.name +
                                    " (one by spi=, one after its bus= number): name them apart with spi=");
    controllers_.push_back(std::move(ctl));
  }
}

std::vector<int> FirmwareRuntime::wired_pins() const {
  std::vector<int> keys;
  for (const auto& l : lines_)
    if (wired(*l)) keys.push_back(l->key);
  std::sort(keys.begin(), keys.end());
  return keys;
}

bool FirmwareRuntime::pin_wired(int key) const {
  const Line* l = line(key);
  return l && wired(*l);
}

bool FirmwareRuntime::wired(const Line& l) {
  return l.cs_chain >= 0 || !l.outputs.empty() || !l.inputs.empty() || !l.sck_chains.empty() || !l.mosi_chains.empty() ||
         !l.miso_chains.empty();
}

// ---------------------------------------------------------------- time

void FirmwareRuntime::set_now(Tick tick) {
  now_ = tick;
  if (!scenario_) {
    board_->time().set_now(tick);
    return;
  }
  // `run`'s scenario moves the board, acting at each step's own tick on the way.
  const std::size_t before = scenario_->log().size();
  scenario_->advance_to(tick);
  if (scenario_->log().size() != before) world_acted();
}

void FirmwareRuntime::call() { spend(timing_.call_ticks); }

void FirmwareRuntime::spend(Tick ticks) {
  if (now_ + ticks >= limit_ticks_) {
    set_now(std::max(now_, limit_ticks_));  // the run ends at the limit itself
    stop_at_limit();
  }
  run_timers_to(now_ + ticks);
  catch_up();
  if (!polled_.empty()) poll_levels();
  if (any_pending_) deliver();
}

void FirmwareRuntime::catch_up() {
  if (board_watches_ == 0 || now_ < next_edge_) return;
  board_->advance_to(now_);
  process_edges();
  next_edge_ = board_->next_edge_tick();
  process_edges();
}

void FirmwareRuntime::sleep_until(Tick tick) {
  const Tick target = std::min(tick, limit_ticks_);
  constexpr Tick kPollTicks = ticks_from_ms(1);
  while (now_ < target) {
    Tick step = target;
    if (scenario_) step = std::min(step, std::max(scenario_->next_tick(), now_ + 1));  // a step acts then: wake for it
    if (board_watches_) {
      catch_up();
      step = std::min(step, next_edge_);
    }
    if (!polled_.empty()) step = std::min(step, now_ + kPollTicks);
    step = std::min(step, std::max(timers_->next_event(), now_));  // a timer event: met at its tick
    set_now(std::max(step, now_));
    timers_->fire_through(now_);
    catch_up();
    if (!polled_.empty()) poll_levels();
    if (any_pending_) deliver();
  }
  if (now_ >= limit_ticks_) stop_at_limit();
}

// ---------------------------------------------------------------- pins

void FirmwareRuntime::set_pin_mode(int key, McuPinMode mode) {
  Line& l = make_line(key);
  l.mode = mode;
  // On an Arduino the pull-up is the output latch (an AVR's PORT bit): INPUT clears it, INPUT_PULLUP sets it.
  if (front_ == FirmwareFront::arduino && mode == McuPinMode::input_pullup) l.latch = true;
  if (front_ == FirmwareFront::arduino && mode == McuPinMode::input) l.latch = false;
  apply_drive(l);
  after_change();
  line_changed(l);
  process_edges();
  if (any_pending_) deliver();
}

McuPinMode FirmwareRuntime::pin_mode(int key) const {
  const Line* l = line(key);
  return l ? l->mode : McuPinMode::input;
}

void FirmwareRuntime::write_pin(int key, bool level) {
  Line& l = make_line(key);
  if (l.latch != level && !wired(l)) {
    l.unmapped_change = ++unmapped_writes_;
  }
  l.latch = level;
  apply_drive(l);
  after_change();
  line_changed(l);
  process_edges();
  if (any_pending_) deliver();
}

bool FirmwareRuntime::pin_latch(int key) const {
  const Line* l = line(key);
  return l && l->latch;
}

bool FirmwareRuntime::read_pin(int key) {
  Line* l = line(key);
  if (!l) return false;
  for (const ChipRef& r : l->outputs) board_->note_output_read(r.chain, r.chip, r.pin);  // the program looks (BUSY, FLAG)
  const bool level = line_level(*l, false);
  process_edges();
  return level;
}

bool FirmwareRuntime::line_level(const Line& l, bool tracked) {
  const bool driving = l.mode == McuPinMode::output || (l.mode == McuPinMode::output_open_drain && !l.latch);
  if (l.cs_chain >= 0) return driving ? l.latch : true;  // pulled up while released
  if (!l.outputs.empty()) {
    bool level = true;  // open drain with a pull-up: low when anything pulls it low
    for (const ChipRef& r : l.outputs)
      level = level && (tracked ? tracked_[r.chain][r.chip][static_cast<unsigned>(r.pin)]
                                : board_->pin_level(r.chain, r.chip, r.pin));
    return driving ? level && l.latch : level;
  }
  if (driving) return l.latch;
  if (!l.miso_chains.empty()) {
    // SDO of every selected chain on the pin, driving it together (read as the AND, as bytes
    // from a controller are); none selected: it floats, and reads as an unconnected input.
    bool any = false, level = true;
    for (const std::size_t chain : l.miso_chains)
      if (const auto sdo = board_->spi_data_out(chain)) {
        any = true;
        level = level && *sdo;
      }
    if (any) return level;
  }
  if (!l.inputs.empty()) {
    const ChipRef& r = l.inputs.front();
    if (r.pin == Pin::SW) {
      board_->catch_up(r.chain);
      return board_->chain(r.chain).chip(r.chip).sw_pin();  // the switch (or the axis) as the chip sees it
    }
    return board_->pin_level(r.chain, r.chip, r.pin);
  }
  if (l.mode == McuPinMode::input_pulldown) return false;
  return l.mode == McuPinMode::input_pullup || l.latch;  // an unconnected input: its pull-up, else low
}

void FirmwareRuntime::apply_drive(Line& l) {
  const bool driving = l.mode == McuPinMode::output || (l.mode == McuPinMode::output_open_drain && !l.latch);
  const int drive = driving ? (l.latch ? 1 : 0) : 2;
  if (drive == l.applied) return;
  l.applied = drive;
  if (l.cs_chain >= 0) {
    const bool selected = drive == 0;
    const auto chain = static_cast<std::size_t>(l.cs_chain);
    if (selected != board_->chip_selected(chain)) {
      if (selected) unmapped_at_select_[chain] = unmapped_writes_;
      if (!selected && !board_->spi_pins(chain).frame_clocked() && board_->chain(chain).bytes_in_frame() == 0)
        unclocked_frame(chain);
      board_->drive_chip_select(chain, selected);
      dirty();
      check_rules();
    }
    return;
  }
  if (!l.sck_chains.empty() || !l.mosi_chains.empty()) drive_spi_pins(l, drive);
  for (const ChipRef& r : l.inputs) {
    if (drive == 2 && r.pin == Pin::SW) continue;  // released: the switch decides
    // Released, STBY_RST is pulled up (running) and STCK down, as boards wire them.
    const bool level = drive == 2 ? r.pin == Pin::STBY_RST : drive == 1;
    board_->drive_pin(r.chain, r.chip, r.pin, level);
    dirty();
  }
}

void FirmwareRuntime::unclocked_frame(std::size_t chain) {
  // One such frame is every start's (a chip select set to output drives low until it is driven
  // high). Pins the description does not map clocked inside it (a byte's eight rising edges
  // on one pin are at least 15 level changes; an LED set up meanwhile is one or two), or a
  // second one before any byte, are a bus the board cannot hear: bit-banged on pins it does not know.
  constexpr std::uint64_t kChangesOfAByte = 15;
  const bool unmapped_inside = unmapped_writes_ - unmapped_at_select_[chain] >= kChangesOfAByte;
  if (!unmapped_inside && (++unclocked_frames_[chain] < 2 || board_->chain(chain).frames() != 0)) return;
  // The pins switched inside the frame (the bus), else every one ever switched; eight at most.
  std::vector<int> keys;
  for (const bool inside : {true, false}) {
    const std::uint64_t since = inside ? unmapped_at_select_[chain] : 0;
    for (const auto& l : lines_)
      if (!wired(*l) && l->unmapped_change > since) keys.push_back(l->key);
    if (!keys.empty()) break;
  }
  std::sort(keys.begin(), keys.end());
  constexpr std::size_t kNamed = 8;
  std::string pins;
  for (std::size_t i = 0; i < std::min(keys.size(), kNamed); ++i) pins += (pins.empty() ? "" : ", ") + to_string(pin_of(keys[i]));
  if (keys.size() > kNamed) pins += " and " + std::to_string(keys.size() - kNamed) + " more";
  const std::string what =
      "a chip-select frame with no clock edge: nothing reached the chips" +
      (pins.empty() ? std::string()
                    : "; the program drives pins " + pins +
                          " the board description does not map (bit-banged SPI? map them with sck_pin=, mosi_pin=, miso_pin=)");
  report_once("unclocked " + std::to_string(chain), board_->chain_name(chain) + ": " + what);
  board_->report_spi_pins(chain, what);
}

void FirmwareRuntime::drive_spi_pins(Line& l, int drive) {
  if (drive == 2) return;  // released: CK and SDI keep the level they had (no pull is modelled)
  const bool level = drive == 1;
  for (const std::size_t chain : l.mosi_chains) board_->drive_spi_data(chain, level);
  if (l.sck_chains.empty()) return;
  bool any_selected = false;
  for (const std::size_t chain : l.sck_chains) {
    const std::uint64_t bytes = board_->spi_pins(chain).bytes_in_frame();
    any_selected = any_selected || board_->chip_selected(chain);
    board_->drive_spi_clock(chain, level);
    if (board_->spi_pins(chain).bytes_in_frame() != bytes) {
      clocked_ = true;  // a whole byte reached the chips
      dirty();
    }
  }
  if (!any_selected && level && ++l.unselected_rising == 8) {
    // A byte's worth of clocks with no chip select of the pin low: it shifts nothing.
    const std::size_t chain = l.sck_chains.front();
    const std::string pin = to_string(pin_of(l.key));
    report_once("sck " + pin, board_->chain_name(chain) + ": clock edges on " + pin + " (sck_pin=) while no chip select of it "
                              "is low: they shift nothing (is cs_pin= the pin the program drives?)");
    board_->report_spi_pins(chain, "clock edges on " + pin + " (sck_pin=) while no chip select of the pin was low: nothing shifts");
  }
  check_rules();
}

void FirmwareRuntime::line_changed(Line& l) {
  if (!l.edges || !l.on_edge) return;
  const bool level = line_level(l, true);
  if (level == l.seen) return;
  l.seen = level;
  if (!(l.edges & (level ? kEdgeRising : kEdgeFalling))) return;
  for (const ChipRef& r : l.outputs) board_->note_output_edge(r.chain, r.chip, r.pin, level);  // the program's interrupt
  l.on_edge(level);
}

void FirmwareRuntime::process_edges() {
  while (!edges_.empty()) {
    std::vector<PinEdge> edges;
    edges.swap(edges_);
    std::stable_sort(edges.begin(), edges.end(), [](const PinEdge& a, const PinEdge& b) { return a.tick < b.tick; });
    // Edges of one tick together: chips wired to one pin that change at the same tick make no glitch.
    for (std::size_t i = 0; i < edges.size();) {
      std::size_t j = i;
      std::vector<int> touched;
      for (; j < edges.size() && edges[j].tick == edges[i].tick; ++j) {
        const PinEdge& e = edges[j];
        if (e.chain >= tracked_.size() || e.chip >= tracked_[e.chain].size()) continue;
        tracked_[e.chain][e.chip][static_cast<unsigned>(e.pin)] = e.level;
        const int key = chip_line_[e.chain][e.chip][static_cast<unsigned>(e.pin)];
        if (key >= 0 && std::find(touched.begin(), touched.end(), key) == touched.end()) touched.push_back(key);
      }
      for (const int key : touched)
        if (Line* l = line(key)) line_changed(*l);
      i = j;
    }
  }
}

void FirmwareRuntime::watch_pin(int key, unsigned edges, std::function<void(bool)> on_edge) {
  Line& l = make_line(key);
  l.edges = edges & kEdgeBoth;
  l.on_edge = l.edges ? std::move(on_edge) : nullptr;
  set_board_watch(l, l.edges != 0 && !l.outputs.empty());
  const bool poll = (l.edges != 0 && l.outputs.empty() && !l.inputs.empty()) || l.level_watch;
  const auto it = std::find(polled_.begin(), polled_.end(), key);
  if (poll && it == polled_.end()) polled_.push_back(key);
  if (!poll && it != polled_.end()) polled_.erase(it);
  process_edges();
  l.seen = line_level(l, true);
}

void FirmwareRuntime::set_board_watch(Line& l, bool watched) {
  if (watched == l.board_watched) return;
  for (const ChipRef& r : l.outputs) {
    board_->catch_up(r.chain);
    board_->watch_pin(r.chain, r.chip, r.pin, watched);
    if (watched) tracked_[r.chain][r.chip][static_cast<unsigned>(r.pin)] = board_->level(r.chain, r.chip, r.pin);
  }
  l.board_watched = watched;
  watched ? ++board_watches_ : --board_watches_;
  next_edge_ = board_watches_ ? 0 : kNever;
}

bool FirmwareRuntime::wait_for_level(int key, bool level, Tick until) {
  Line& l = make_line(key);
  // A chip output is waited for to its exact edge: the board is asked to watch it meanwhile.
  const bool temporary = !l.outputs.empty() && !l.board_watched;
  if (temporary) set_board_watch(l, true);
  bool reached = true;
  while (read_pin(key) != level) {
    if (now_ >= until) {
      reached = false;
      break;
    }
    Tick step = until;
    if (board_watches_) {
      catch_up();
      step = std::min(step, next_edge_);
    }
    if (l.outputs.empty()) step = std::min(step, now_ + kTicksPerMicrosecond);  // nothing to predict: look each microsecond
    sleep_until(std::max(step, now_ + 1));
  }
  if (temporary) {
    set_board_watch(l, false);
    process_edges();
  }
  return reached;
}

void FirmwareRuntime::watch_level(int key, bool level, std::function<void(bool)> on_level) {
  Line& l = make_line(key);
  l.level_watch = static_cast<bool>(on_level);
  l.watched_level = level;
  l.on_level = std::move(on_level);
  const auto it = std::find(polled_.begin(), polled_.end(), key);
  const bool poll = l.level_watch || (l.edges != 0 && l.outputs.empty() && !l.inputs.empty());
  if (poll && it == polled_.end()) polled_.push_back(key);
  if (!poll && it != polled_.end()) polled_.erase(it);
}

void FirmwareRuntime::poll_levels() {
  for (std::size_t i = 0; i < polled_.size(); ++i) {
    Line* l = line(polled_[i]);
    if (!l) continue;
    if (l->level_watch) {
      if (line_level(*l, l->board_watched) == l->watched_level && l->on_level) l->on_level(l->watched_level);
    } else {
      // A switch the axis drives: the board cannot say ahead when it changes, so look now.
      const bool level = line_level(*l, false);
      if (level != l->seen) {
        l->seen = level;
        if (l->edges & (level ? kEdgeRising : kEdgeFalling)) l->on_edge(level);
      }
    }
  }
  process_edges();
}

// ---------------------------------------------------------------- interrupts

int FirmwareRuntime::add_irq(std::function<void()> handler) {
  irqs_.push_back(Irq{std::move(handler), true, false, 0});
  return static_cast<int>(irqs_.size() - 1);
}

void FirmwareRuntime::set_irq_enabled(int irq, bool enabled) {
  Irq& q = irqs_.at(static_cast<std::size_t>(irq));
  q.enabled = enabled;
  if (enabled && q.pending) any_pending_ = true;
}

bool FirmwareRuntime::irq_enabled(int irq) const { return irqs_.at(static_cast<std::size_t>(irq)).enabled; }

void FirmwareRuntime::pend_irq(int irq) {
  Irq& q = irqs_.at(static_cast<std::size_t>(irq));
  if (!q.pending) q.since = now_;
  q.pending = true;
  if (q.enabled) any_pending_ = true;
}

void FirmwareRuntime::clear_irq(int irq) { irqs_.at(static_cast<std::size_t>(irq)).pending = false; }

bool FirmwareRuntime::irq_pending(int irq) const { return irqs_.at(static_cast<std::size_t>(irq)).pending; }

void FirmwareRuntime::enable_interrupts() {
  irqs_on_ = true;
  if (any_pending_) deliver();
}

void FirmwareRuntime::deliver() {
  if (!irqs_on_ || in_irq_) return;
  any_pending_ = false;
  // One pass over what is pending now, oldest first (ties: the lower number first). What a
  // handler leaves or makes pending runs at the next call, so a handler that never clears its
  // source cannot hold time still.
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < irqs_.size(); ++i)
    if (irqs_[i].pending && irqs_[i].enabled) order.push_back(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return irqs_[a].since < irqs_[b].since; });
  for (const std::size_t i : order) {
    Irq& q = irqs_[i];
    if (!q.pending || !q.enabled) continue;
    if (!irqs_on_) break;
    q.pending = false;
    in_irq_ = true;
    q.handler();
    in_irq_ = false;
  }
  for (const Irq& q : irqs_)
    if (q.pending && q.enabled) any_pending_ = true;
}

// ---------------------------------------------------------------- SPI

int FirmwareRuntime::controller(std::string_view name) const {
  const auto canonical = parse_spi_controller(name);
  for (std::size_t i = 0; i < controllers_.size(); ++i)
    if (canonical && controllers_[i].name == *canonical) return static_cast<int>(i);
  return controllers_.size() == 1 ? 0 : -1;
}

std::vector<std::string> FirmwareRuntime::controller_names() const {
  std::vector<std::string> names;
  for (const Controller& c : controllers_) names.push_back(c.name);
  return names;
}

void FirmwareRuntime::report_once(const std::string& key, const std::string& text) {
  if (std::find(reported_.begin(), reported_.end(), key) != reported_.end()) return;
  reported_.push_back(key);
  log(text);
}

void FirmwareRuntime::transfer(int controller, const BusSettings& settings, std::span<const std::uint8_t> tx,
                               std::span<std::uint8_t> rx) {
  const Controller& ctl = controllers_.at(static_cast<std::size_t>(controller));
  // A mode other than 3, LSB first, words other than 8 bits, SCK above 5 MHz: the board clocks
  // them as the wire gives them and its sanitizer names them (check=).
  std::size_t selected = 0;
  for (const std::size_t c : ctl.chains) selected += board_->chip_selected(c) ? 1 : 0;
  if (selected == 0)
    report_once(ctl.name + " none", ctl.name + ": bytes clocked while no chip select of the bus is low (is cs_pin= "
                                               "the pin the program drives?)");
  if (selected > 1)
    report_once(ctl.name + " two", ctl.name + ": bytes clocked with " + std::to_string(selected) +
                                        " chip selects low: every selected chain takes them and they drive MISO together");
  const Tick end = board_->clock_bytes(ctl.chains, tx, rx, settings);
  clocked_ = clocked_ || !tx.empty();
  check_rules();
  run_timers_to(end);  // a timer event inside the bytes' bus time is met at its tick
  after_change();
  if (board_watches_) dirty();
  process_edges();
  if (now_ >= limit_ticks_) stop_at_limit();
  if (any_pending_) deliver();
}

// ---------------------------------------------------------------- timers (firmware/timers.cpp)

bool FirmwareRuntime::drive_pulse_train(int key, const PulseTrain* train) {
  Line* l = line(key);
  if (!l || l->inputs.empty()) return false;
  for (const ChipRef& r : l->inputs) {
    if (train)
      board_->drive_pulse_train(r.chain, r.chip, r.pin, *train);
    else
      board_->stop_pulse_train(r.chain, r.chip, r.pin, false);
  }
  l->applied = -1;  // the pin's next drive by the program reaches the board whatever it was
  dirty();
  process_edges();
  return true;
}

void FirmwareRuntime::run_timers_to(Tick tick) {
  for (Tick at = timers_->next_event(); at <= tick; at = timers_->next_event()) {
    set_now(std::max(at, now_));
    timers_->fire_through(now_);
    catch_up();
    if (any_pending_) deliver();  // the handler runs at its event's tick
  }
  set_now(std::max(tick, now_));
}

// ---------------------------------------------------------------- the run

void FirmwareRuntime::log(std::string_view text) const {
  if (log_) log_(text);
}

void FirmwareRuntime::finish() {
  if (finished_) return;
  finished_ = true;
  for (std::size_t i = 0; i < board_->chain_count(); ++i) board_->stop_recording(i);
  // L6470EMU_COVERAGE: what the program met, merged into the file (other processes' too).
  if (!config_.coverage.empty())
    if (const std::string error = merge_into_coverage_file(config_.coverage, board_->coverage()); !error.empty())
      log("coverage not written: " + error);
}

void FirmwareRuntime::stop(int status, const std::string& why) {
  if (!why.empty()) log(why);
  finish();
  std::fflush(nullptr);
  std::exit(status);
}

void FirmwareRuntime::check_rules() {
  if (!board_->sanitizer().failed()) return;
  const std::optional<std::string> report = board_->take_check_failure();
  if (!report) return;
  // As a sanitizer: the report on standard error whatever log= says, the run's first line in
  // the log too when it is elsewhere; recordings finished; the sanitizer's exit status.
  std::fflush(stdout);
  std::fputs(report->c_str(), stderr);
  if (report->empty() || report->back() != '\n') std::fputc('\n', stderr);
  std::fflush(stderr);
  if (config_.log != "stderr") {
    const std::string first = report->substr(0, report->find('\n'));
    log(first.substr(std::min(first.size(), first.find("driver sanitizer"))) + " (the run ends with exit status " +
        std::to_string(kSanitizerExitStatus) + ")");
  }
  // Under `l6470emu run`: the report says why the program ended (run's own exit status for it).
  if (end_hook_) end_hook_(RunEnd::sanitizer, report->substr(0, report->find('\n')));
  stop(kSanitizerExitStatus, "");
}

void FirmwareRuntime::stop_at_limit() {
  if (now_ >= run_limit_ && run_limit_ <= timing_.limit_ticks) {
    // `l6470emu run`'s limit, before the program's own: the report says so, as the preload's does.
    if (end_hook_) end_hook_(RunEnd::timeout, "");
    stop(kTimeoutExitStatus, "");
  }
  std::string why = "firmware run stopped at its time limit: " + short_seconds_text(now_) + " of virtual time (limit=" +
                    limit_text(timing_.limit_ticks) + ")";
  if (front_ == FirmwareFront::arduino) why += "; loop() had run " + counted(loops, "time");
  stop(0, why);
}

// ---------------------------------------------------------------- under `l6470emu run`

void FirmwareRuntime::bind_scenario(const Scenario& scenario) {
  scenario_.reset();
  scenario_ = std::make_unique<ScenarioRunner>(*board_, scenario, [this](std::string_view bytes) { serial_arrive(bytes); });
  scenario_->advance_to(now_);  // steps at tick 0 act before the program's first call
  world_acted();
}

int FirmwareRuntime::serial_peek() const {
  return serial_available() ? static_cast<unsigned char>(serial_in_[serial_at_]) : -1;
}

int FirmwareRuntime::serial_read() {
  const int c = serial_peek();
  if (c < 0) return c;
  if (++serial_at_ == serial_in_.size()) {
    serial_in_.clear();  // all read: the queue starts again
    serial_at_ = 0;
  }
  return c;
}

bool FirmwareRuntime::finish_scenario(ScenarioOutcome& out) {
  if (!scenario_) return false;
  scenario_->finish();
  out = scenario_->outcome();
  return true;
}

void FirmwareRuntime::set_run_limit(Tick limit) {
  run_limit_ = limit;
  limit_ticks_ = std::min(timing_.limit_ticks, run_limit_);
}

void FirmwareRuntime::set_end_hook(std::function<void(RunEnd, std::string_view)> hook) { end_hook_ = std::move(hook); }

void FirmwareRuntime::after_change() {
  if (!scenario_) return;
  const std::size_t before = scenario_->log().size();
  scenario_->after_transfer();
  if (scenario_->log().size() != before) world_acted();
}

void FirmwareRuntime::world_acted() {
  if (board_watches_) dirty();
  process_edges();
}

// ---------------------------------------------------------------- the program's runtime

extern "C" {
/// Set by l6470emu_add_sketch / l6470emu_add_hal_program BOARD (a description) or BOARD_FILE.
const char* l6470emu_fw_default_board(void) __attribute__((weak));
const char* l6470emu_fw_default_board_file(void) __attribute__((weak));
/// Defined by a program built with the CMake functions (CHECK, default error): the sanitizer's
/// level when neither the description nor L6470EMU_CHECK says.
const char* l6470emu_fw_default_check(void) __attribute__((weak));
/// Defined (weak, in every file that includes it) by Arduino.h when the sketch is built for a
/// board other than an Uno (l6470emu_add_sketch's ARDUINO_BOARD): "nucleo_f401re".
const char* l6470emu_fw_arduino_board(void) __attribute__((weak));
}

namespace {

FirmwareRuntime* g_runtime = nullptr;

[[noreturn]] void fail_to_start(const std::string& line) {
  std::fflush(stdout);
  std::fprintf(stderr, "%s\n", line.c_str());
  std::exit(2);
}

// Reads a description file with stdio: at most kMaxConfigBytes + 1 bytes.
ParseResult read_description_file(const std::string& path) {
  const std::string where = "l6470emu: config file " + shown_text(path, 200) + ": ";
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return {std::nullopt, {where + "cannot be read"}};
  std::string text(kMaxConfigBytes + 1, '\0');
  const std::size_t got = std::fread(text.data(), 1, text.size(), f);
  const bool error = std::ferror(f) != 0;
  std::fclose(f);
  if (error) return {std::nullopt, {where + "cannot be read (a directory?)"}};
  if (got > kMaxConfigBytes) return {std::nullopt, {where + "longer than 1 MiB (a board description is a few lines)"}};
  text.resize(got);
  return parse_board_config(text, path);
}

LineSink make_log(const std::string& where) {
  if (where == "off") return {};
  std::FILE* out = stderr;
  if (where != "stderr") {
    out = std::fopen(where.c_str(), "a");
    if (!out) {
      std::fprintf(stderr, "l6470emu: log file %s cannot be opened: diagnostics go to stderr\n", quoted_text(where).c_str());
      out = stderr;
    }
  }
  return [out](std::string_view line) {
    std::fflush(stdout);  // what the program printed before comes first
    std::fprintf(out, "l6470emu: %.*s\n", static_cast<int>(line.size()), line.data());
    std::fflush(out);
  };
}

void finish_at_exit() {
  if (g_runtime) g_runtime->finish();
}

}  // namespace

FirmwareRuntime* existing_firmware_runtime() { return g_runtime; }

FirmwareRuntime* open_firmware_runtime(const char* description, FirmwareFront front, std::string& error) {
  if (g_runtime) {
    error = "l6470emu: firmware: the board is already open (one board per program)";
    return nullptr;
  }
  // A mistyped L6470EMU_* variable is named at start-up, as the preload names it.
  if (const std::string unknown = unknown_environment_variables(
          environ, "firmware programs read L6470EMU_CHAIN, _CONFIG, _LOG, _TRACE, _CHECK, _CHECK_ALLOW, _COVERAGE");
      !unknown.empty())
    std::fputs(unknown.c_str(), stderr);
  ParseResult parsed;
  const char* chain = std::getenv("L6470EMU_CHAIN");
  const char* file = std::getenv("L6470EMU_CONFIG");
  // Under `l6470emu run` the run's board (its L6470EMU_CHAIN) is the program's, even over a
  // description the program gives: run checked its scenario against it and judges by it.
  const bool run_board = chain && *chain && (std::getenv(kRunReportEnv) || std::getenv(kRunScenarioEnv));
  if (description && !run_board) {
    parsed = parse_board_config(description, "the program's description");
  } else if (chain && *chain) {
    parsed = parse_board_config(chain, "L6470EMU_CHAIN");
  } else if (file && *file) {
    parsed = read_description_file(file);
  } else if (const char* built = l6470emu_fw_default_board ? l6470emu_fw_default_board() : nullptr; built && *built) {
    parsed = parse_board_config(built, "BOARD");
  } else if (const char* path = l6470emu_fw_default_board_file ? l6470emu_fw_default_board_file() : nullptr;
             path && *path) {
    parsed = read_description_file(path);
  } else {
    parsed = parse_board_config("chips=L6470", "the default board");
  }
  if (!parsed.config) {
    error = parsed.error.message;
    return nullptr;
  }
  BoardConfig config = std::move(*parsed.config);
  if (const char* log = std::getenv("L6470EMU_LOG"); log && *log) config.log = log;
  if (const char* trace = std::getenv("L6470EMU_TRACE"); trace && *trace) config.trace = trace;
  if (const char* coverage = std::getenv(kCoverageEnv); coverage && *coverage) {
    if (const std::string why = check_coverage_output(coverage); !why.empty()) {
      error = std::string("l6470emu: ") + kCoverageEnv + ": " + why;
      return nullptr;
    }
    config.coverage = coverage;
  }
  // The driver sanitizer, as the preload reads it; below the description's check= and the
  // environment, the level the program was built with.
  // (Under `l6470emu run` the run's board decides, as it does the board itself.)
  if (const char* built = l6470emu_fw_default_check ? l6470emu_fw_default_check() : nullptr;
      built && *built && !config.check_given && !run_board) {
    std::string why;
    const auto level = parse_check_level(built, why);
    if (!level) {
      error = "l6470emu: the program's CHECK " + why;
      return nullptr;
    }
    config.check.level = *level;
  }
  if (const char* check = std::getenv("L6470EMU_CHECK"); check && *check) {
    std::string why;
    const auto level = parse_check_level(check, why);
    if (!level) {
      error = "l6470emu: L6470EMU_CHECK " + why;
      return nullptr;
    }
    config.check.level = *level;
  }
  if (const char* allow = std::getenv("L6470EMU_CHECK_ALLOW"); allow && *allow) {
    std::string why;
    const auto rules = parse_rule_list(allow, why);
    if (!rules) {
      error = "l6470emu: L6470EMU_CHECK_ALLOW " + why;
      return nullptr;
    }
    config.check.allowed = *rules;
  }
  ArduinoBoard arduino_board = ArduinoBoard::uno;
  if (const char* name = l6470emu_fw_arduino_board ? l6470emu_fw_arduino_board() : nullptr; name && *name) {
    const auto b = parse_arduino_board(name);
    if (!b) {
      error = "l6470emu: firmware: the sketch's Arduino board " + quoted_text(name) + " is none of uno, nucleo_f401re";
      return nullptr;
    }
    arduino_board = *b;
  }
  std::unique_ptr<FirmwareRuntime> runtime;
  try {
    runtime = std::make_unique<FirmwareRuntime>(config, front, make_log(config.log), arduino_board);
  } catch (const std::exception& e) {
    error = std::string("l6470emu: firmware: ") + e.what();
    return nullptr;
  }
  if (!config.trace.empty()) {
    if (const std::string e = runtime->board().start_recording_all(config.trace); !e.empty()) {
      error = "l6470emu: trace " + quoted_text(config.trace) + ": " + e;
      return nullptr;
    }
  }
  if (!config.coverage.empty()) runtime->board().enable_coverage();
  g_runtime = runtime.release();  // lives until the program ends
  std::atexit(finish_at_exit);
  // Under `l6470emu run`: its scenario, its time limit, its report (at exit, before finish_at_exit).
  if (const std::string why = join_run(*g_runtime); !why.empty()) fail_to_start(why);
  return g_runtime;
}

FirmwareRuntime& firmware_runtime(FirmwareFront front) {
  if (g_runtime) return *g_runtime;
  std::string error;
  FirmwareRuntime* r = open_firmware_runtime(nullptr, front, error);
  if (!r) fail_to_start(error);
  return *r;
}

}  // namespace l6470emu
