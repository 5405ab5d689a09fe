// libFuzzer harness of the SPI face: the input picks a chain (1-8 chips, any variants and
// quirks), then CS frames (on the byte path, and on the bit-level face in any SPI mode and bit
// order, with deselects shorter than t_disCS), pin changes, backdoor faults and time advances, run in lockstep
// on two chains (fast and reference motion engines). Checked at every step: ABS_POS stays
// 22-bit, a GetStatus leaves exactly the conditions that persist latched, both engines agree
// (MISO, STATUS, pins, motion state), a frame's MISO is as long as its MOSI. No oracle for
// what a command should do: core/ tests own that.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <array>
#include <vector>

#include "board/trace_recorder.hpp"
#include "core/status.hpp"
#include "fuzz_support.hpp"

using namespace l6470emu;

namespace {

/// Simulated time both chains may cover per input: the reference engine costs one step of
/// work per tick while a motor moves (2^17 ticks = 33 ms of motion).
constexpr Tick kTickBudget = Tick{1} << 17;

/// The physical conditions the harness imposed on one chip (what GetStatus may leave latched).
struct Conditions {
  AlarmFlags flags;
};

/// Bits of STATUS that belong to latched flags in `layout`.
std::uint16_t latched_mask(const StatusLayout& layout) {
  const std::uint16_t none = encode_latched(layout, AlarmFlags{});
  std::uint16_t mask = 0;
  auto with = [&](auto set) {
    AlarmFlags a;
    set(a);
    mask = static_cast<std::uint16_t>(mask | (encode_latched(layout, a) ^ none));
  };
  with([](AlarmFlags& a) { a.uvlo = true; });
  with([](AlarmFlags& a) { a.uvlo_adc = true; });
  with([](AlarmFlags& a) { a.ocd = true; });
  with([](AlarmFlags& a) { a.stall_a = true; });
  with([](AlarmFlags& a) { a.stall_b = true; });
  with([](AlarmFlags& a) { a.wrong_cmd = true; });
  with([](AlarmFlags& a) { a.notperf_cmd = true; });
  with([](AlarmFlags& a) { a.sw_evn = true; });
  for (Thermal t : {Thermal::warning, Thermal::bridge_shutdown, Thermal::device_shutdown})
    with([t](AlarmFlags& a) { a.thermal = t; });
  return mask;
}

class Harness {
 public:
  explicit Harness(FuzzedDataProvider& in) : in_(in) {
    const std::size_t n = in_.ConsumeIntegralInRange<std::size_t>(1, 8);
    const auto variants = all_variants();
    std::vector<Chip> chips;
    for (std::size_t i = 0; i < n; ++i) {
      const Variant& v = *variants[in_.ConsumeIntegralInRange<std::size_t>(0, variants.size() - 1)];
      const std::uint8_t q = in_.ConsumeIntegral<std::uint8_t>();
      Quirks quirks;
      quirks.read_only_write = (q & 1) ? ReadOnlyWrite::notperf_after_value : ReadOnlyWrite::wrong_cmd_at_command_byte;
      quirks.bemf_write = (q & 2) ? BemfWriteCondition::when_stopped : BemfWriteCondition::when_hiz;
      quirks.stall_bits = (q & 4) ? StallBitOrder::a_on_15 : StallBitOrder::a_on_14;
      quirks.reset_device = static_cast<ResetDeviceWhenEnabled>((q >> 3) % 3);
      chips.emplace_back(v, quirks);
    }
    fast_ = std::make_unique<Chain>(chips);
    ref_ = std::make_unique<Chain>(std::move(chips));
    ref_->set_motion_engine(MotionEngine::reference);
    conditions_.resize(n);
    // Comparing after every step makes both engines work the motion out at every step; without
    // it the fast engine's lazy paths (long skips between looks) get exercised too.
    compare_every_step_ = in_.ConsumeBool();
  }

  void run() {
    check_all();
    while (in_.remaining_bytes() > 0) {
      switch (in_.ConsumeIntegralInRange<int>(0, 10)) {
        case 0:
        case 1:
        case 2: raw_frame(); break;
        case 3:
        case 4: command(); break;
        case 5: advance(); break;
        case 6: pin(); break;
        case 7: fault(); break;
        case 8: poll_status(); break;
        case 9: split_frame(); break;
        case 10: wire_frame(); break;
      }
      if (compare_every_step_) check_all();
    }
    check_all();
  }

 private:
  std::size_t size() const { return fast_->size(); }
  std::size_t pick_chip() { return in_.ConsumeIntegralInRange<std::size_t>(0, size() - 1); }

  // ---- SPI -------------------------------------------------------------------

  /// Which chips will decode a GetStatus at the coming CS rising edge (inside a frame).
  std::vector<std::uint8_t> get_status_decoders(Chain& c) {
    std::vector<std::uint8_t> d(size(), 0);
    if (c.bytes_in_frame() == 0) return d;
    for (std::size_t i = 0; i < size(); ++i) {
      const Chip& chip = c.chip(i);
      // (A chip deaf to this frame decodes nothing; one power-cycled at its end latches UVLO anew.)
      d[i] = chip.spi_enabled() && !chip.collecting_arguments() && c.shift_register(i) == 0xD0 && c.hears_frame(i) &&
             !power_cycle_at_rise_[i];
    }
    return d;
  }

  /// Ends the frame on both chains and checks the GetStatus latching rule.
  void deselect_both() {
    const std::vector<std::uint8_t> gs = get_status_decoders(*fast_);
    FUZZ_CHECK(gs == get_status_decoders(*ref_), "the chains disagree on which chips decode GetStatus");
    fast_->deselect();
    ref_->deselect();
    power_cycle_at_rise_.assign(size(), false);
    for (std::size_t i = 0; i < size(); ++i)
      if (gs[i]) {
        check_status_after_get_status(fast_->chip(i), i, "fast");
        check_status_after_get_status(ref_->chip(i), i, "reference");
      }
  }

  /// After a GetStatus, the latched flags are exactly the conditions that persist.
  void check_status_after_get_status(const Chip& chip, std::size_t i, const char* which) {
    const StatusLayout& layout = chip.status_layout();
    const std::uint16_t mask = latched_mask(layout);
    const std::uint16_t expected = static_cast<std::uint16_t>(encode_latched(layout, conditions_[i].flags) & mask);
    const std::uint16_t got = static_cast<std::uint16_t>(chip.status() & mask);
    FUZZ_CHECK(got == expected,
               "%s chain, chip %zu (%.*s): after GetStatus the latched STATUS bits are 0x%04X, the conditions that "
               "persist give 0x%04X",
               which, i, static_cast<int>(chip.variant().name.size()), chip.variant().name.data(), got, expected);
  }

  void exchange_both(const std::vector<std::uint8_t>& tx, int how) {
    std::vector<std::uint8_t> rf(tx.size(), 0xEE), rr(tx.size(), 0xEE);
    if (how == 0) {
      for (std::size_t i = 0; i < tx.size(); ++i) {
        rf[i] = fast_->exchange(tx[i]);
        rr[i] = ref_->exchange(tx[i]);
      }
    } else {
      fast_->exchange(tx, rf);
      ref_->exchange(tx, rr);
    }
    FUZZ_CHECK(rf == rr, "MISO differs between the fast and the reference chain");
  }

  void frame(const std::vector<std::uint8_t>& tx) {
    const int how = in_.ConsumeIntegralInRange<int>(0, 2);
    if (how == 2) {
      // Chain::frame as one call: its MISO must be as long as the frame.
      if (!std::any_of(tx.begin(), tx.end(), [](std::uint8_t b) { return b == 0xD0; })) {
        const std::vector<std::uint8_t> rf = fast_->frame(tx), rr = ref_->frame(tx);
        FUZZ_CHECK(rf.size() == tx.size() && rr.size() == tx.size(), "frame of %zu bytes returned %zu MISO bytes",
                   tx.size(), rf.size());
        FUZZ_CHECK(rf == rr, "MISO differs between the fast and the reference chain");
        return;
      }
    }
    fast_->select();
    ref_->select();
    exchange_both(tx, how);
    deselect_both();
  }

  void raw_frame() {
    const std::size_t len = in_.ConsumeIntegralInRange<std::size_t>(0, 3 * size() + 2);
    frame(in_.ConsumeBytes<std::uint8_t>(len));
  }

  /// CS held low across a time advance, a pin change or a fault (the chips decode at CS rise).
  void split_frame() {
    fast_->select();
    ref_->select();
    exchange_both(in_.ConsumeBytes<std::uint8_t>(in_.ConsumeIntegralInRange<std::size_t>(0, 2 * size())), 1);
    switch (in_.ConsumeIntegralInRange<int>(0, 2)) {
      case 0: advance(); break;
      case 1: pin(); break;
      case 2: fault(); break;
    }
    exchange_both(in_.ConsumeBytes<std::uint8_t>(in_.ConsumeIntegralInRange<std::size_t>(0, 2 * size())), 0);
    deselect_both();
  }

  /// A frame from a host with any wire settings (mode, bit order), in up to two runs of bytes
  /// that may differ in mode, after a CS-high time that may be shorter than t_disCS.
  void wire_frame() {
    auto settings = [this] {
      WireSettings w;
      w.mode = in_.ConsumeIntegralInRange<std::uint8_t>(0, 3);
      w.lsb_first = in_.ConsumeBool();
      return w;
    };
    advance_by(in_.ConsumeIntegralInRange<Tick>(0, 6));
    fast_->select_wire();
    ref_->select_wire();
    for (int run = in_.ConsumeIntegralInRange<int>(1, 2); run > 0; --run) {
      const WireSettings w = settings();
      const std::vector<std::uint8_t> tx = in_.ConsumeBytes<std::uint8_t>(in_.ConsumeIntegralInRange<std::size_t>(0, 2 * size() + 1));
      std::vector<std::uint8_t> rf(tx.size(), 0xEE), rr(tx.size(), 0xEE);
      fast_->exchange_wire(tx, rf, w);
      ref_->exchange_wire(tx, rr, w);
      FUZZ_CHECK(rf == rr, "MISO differs between the fast and the reference chain (mode %u)", unsigned{w.mode});
    }
    const std::vector<std::uint8_t> gs = get_status_decoders(*fast_);
    FUZZ_CHECK(gs == get_status_decoders(*ref_), "the chains disagree on which chips decode GetStatus");
    fast_->deselect_wire();
    ref_->deselect_wire();
    for (std::size_t i = 0; i < size(); ++i) {
      FUZZ_CHECK(fast_->sdo_latch(i) == ref_->sdo_latch(i), "chip %zu's SDO latch differs between the chains", i);
      if (gs[i]) {
        check_status_after_get_status(fast_->chip(i), i, "fast");
        check_status_after_get_status(ref_->chip(i), i, "reference");
      }
    }
  }

  /// A well-formed command for one chip, sent as one frame per byte with NOPs for the others.
  void command() {
    const std::size_t k = pick_chip();
    static constexpr std::array<std::uint8_t, 24> kOpcodes = {
        0x00, 0x40, 0x41, 0x50, 0x51, 0x58, 0x59, 0x60, 0x68, 0x69, 0x70, 0x78,
        0x82, 0x8B, 0x92, 0x9B, 0xB0, 0xC0, 0xD0, 0xA0, 0xA8, 0xB8, 0x18, 0x38};
    std::uint8_t op = in_.ConsumeBool() ? kOpcodes[in_.ConsumeIntegralInRange<std::size_t>(0, kOpcodes.size() - 1)]
                                        : in_.ConsumeIntegral<std::uint8_t>();
    if (in_.ConsumeBool()) op = in_.ConsumeIntegralInRange<std::uint8_t>(0x01, 0x1F);  // SetParam
    const Opcode o = fast_->chip(k).variant().opcodes[op];
    std::vector<std::uint8_t> bytes = {op};
    for (unsigned a = 0; a < o.arg_bytes; ++a) bytes.push_back(in_.ConsumeIntegral<std::uint8_t>());
    if (o.command == Command::GetParam || o.command == Command::GetStatus)
      bytes.insert(bytes.end(), 3, 0x00);  // clock the answer out
    for (std::uint8_t b : bytes) {
      std::vector<std::uint8_t> tx(size(), 0x00);
      tx[k] = b;
      frame(tx);
      maybe_advance_a_little();
    }
  }

  /// GetStatus to every chip, then its answer clocked out.
  void poll_status() {
    frame(std::vector<std::uint8_t>(size(), 0xD0));
    maybe_advance_a_little();
    frame(std::vector<std::uint8_t>(size(), 0x00));
    frame(std::vector<std::uint8_t>(size(), 0x00));
  }

  // ---- time, pins, faults ------------------------------------------------------

  void advance_by(Tick dt) {
    dt = std::min(dt, kTickBudget - used_);
    used_ += dt;
    const Tick t = fast_->now() + dt;
    fast_->advance_to(t);
    ref_->advance_to(t);
  }

  void maybe_advance_a_little() {
    if (in_.remaining_bytes() > 0 && in_.ConsumeBool()) advance_by(in_.ConsumeIntegralInRange<Tick>(0, 64));
  }

  void advance() {
    switch (in_.ConsumeIntegralInRange<int>(0, 3)) {
      case 0: advance_by(in_.ConsumeIntegralInRange<Tick>(0, 255)); break;
      case 1: advance_by(in_.ConsumeIntegralInRange<Tick>(0, 65535)); break;
      case 2: advance_by(in_.ConsumeIntegral<std::uint32_t>()); break;
      case 3: {
        // To the next event of either chain (at most the budget).
        const Tick next = std::min(fast_->next_event_tick(), ref_->next_event_tick());
        if (next != kNever && next > fast_->now()) advance_by(next - fast_->now());
        break;
      }
    }
  }

  void pin() {
    const std::size_t k = pick_chip();
    const bool level = in_.ConsumeBool();
    switch (in_.ConsumeIntegralInRange<int>(0, 3)) {
      case 0:
        fast_->chip(k).set_sw_pin(level);
        ref_->chip(k).set_sw_pin(level);
        break;
      case 3:  // an L6474's direction; the other parts have no DIR pin
        fast_->chip(k).set_dir_pin(level);
        ref_->chip(k).set_dir_pin(level);
        break;
      case 1:
        fast_->chip(k).set_stck_pin(level);
        ref_->chip(k).set_stck_pin(level);
        break;
      case 2:
        fast_->chip(k).set_stby_rst_pin(level);
        ref_->chip(k).set_stby_rst_pin(level);
        break;
    }
  }

  void fault() {
    const std::size_t k = pick_chip();
    // Every backdoor event: the chip's own conditions, a brown-out and the wire's one-shot faults.
    const auto f = static_cast<TraceFault>(in_.ConsumeIntegralInRange<int>(0, kTraceFaultCount - 1));
    const std::uint8_t value = f == TraceFault::ADCIN       ? in_.ConsumeIntegral<std::uint8_t>()
                               : f == TraceFault::THERMAL   ? in_.ConsumeIntegralInRange<std::uint8_t>(0, 3)
                               : f == TraceFault::MISO_FLIP ? in_.ConsumeIntegralInRange<std::uint8_t>(0, 7)
                               : f == TraceFault::POWER_CYCLE || f == TraceFault::LOST_FRAME ? std::uint8_t{0}
                                                                                             : in_.ConsumeBool();
    apply_fault(*fast_, k, f, value);
    apply_fault(*ref_, k, f, value);
    if (f == TraceFault::POWER_CYCLE && fast_->selected()) power_cycle_at_rise_.at(k) = true;  // it waits for CS to rise
    AlarmFlags& c = conditions_[k].flags;
    switch (f) {
      case TraceFault::UVLO: c.uvlo = value != 0; break;
      case TraceFault::UVLO_ADC: c.uvlo_adc = value != 0; break;
      case TraceFault::OCD: c.ocd = value != 0; break;
      case TraceFault::STALL_A: c.stall_a = value != 0; break;
      case TraceFault::STALL_B: c.stall_b = value != 0; break;
      case TraceFault::THERMAL: {
        // Shutdown has hysteresis: it ends only when the die is back to normal.
        const auto t = static_cast<Thermal>(value);
        if (!(c.thermal >= Thermal::bridge_shutdown && t == Thermal::warning)) c.thermal = t;
        break;
      }
      case TraceFault::ADCIN:
      case TraceFault::POWER_CYCLE:  // the conditions outlast a brown-out
      case TraceFault::MISO_FLIP:
      case TraceFault::LOST_FRAME:
        break;
    }
  }

  // ---- invariants -------------------------------------------------------------

  void check_all() {
    FUZZ_CHECK(fast_->now() == ref_->now(), "the chains' times differ");
    for (std::size_t i = 0; i < size(); ++i) {
      const Chip& f = fast_->chip(i);
      const Chip& r = ref_->chip(i);
      for (const Chip* c : {&f, &r}) {
        const std::int32_t pos = c->position();
        FUZZ_CHECK(pos >= -(1 << 21) && pos < (1 << 21), "chip %zu: ABS_POS %d is outside 22 bits", i, pos);
        const std::uint32_t raw = c->peek(Reg::ABS_POS);
        FUZZ_CHECK(raw <= 0x3FFFFF, "chip %zu: GetParam(ABS_POS) 0x%X is wider than 22 bits", i, raw);
        FUZZ_CHECK(c->peek(Reg::EL_POS) <= 0x1FF, "chip %zu: EL_POS wider than 9 bits", i);
      }
      FUZZ_CHECK(f.status() == r.status(), "chip %zu at tick %llu: STATUS fast 0x%04X, reference 0x%04X", i,
                 static_cast<unsigned long long>(f.now()), f.status(), r.status());
      FUZZ_CHECK(f.busy_sync_pin() == r.busy_sync_pin(), "chip %zu: BUSY pin differs between the engines", i);
      FUZZ_CHECK(f.flag_pin() == r.flag_pin(), "chip %zu: FLAG pin differs between the engines", i);
      FUZZ_CHECK(f.motion() == r.motion(),
                 "chip %zu at tick %llu: motion state differs (speed %llu vs %llu, pos %d vs %d, frac %llu vs %llu)", i,
                 static_cast<unsigned long long>(f.now()), static_cast<unsigned long long>(f.motion().speed),
                 static_cast<unsigned long long>(r.motion().speed), f.motion().abs_pos, r.motion().abs_pos,
                 static_cast<unsigned long long>(f.motion().frac), static_cast<unsigned long long>(r.motion().frac));
      for (Reg id : {Reg::SPEED, Reg::MARK, Reg::EL_POS})
        FUZZ_CHECK(f.peek(id) == r.peek(id), "chip %zu: register %d differs between the engines", i,
                   static_cast<int>(id));
    }
  }

  FuzzedDataProvider& in_;
  std::unique_ptr<Chain> fast_, ref_;
  std::vector<bool> power_cycle_at_rise_ = std::vector<bool>(8, false);  // per chip (at most 8)
  std::vector<Conditions> conditions_;
  bool compare_every_step_ = false;
  Tick used_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  FuzzedDataProvider in(data, size);
  Harness h(in);
  h.run();
  return 0;
}
