// Words for opcodes and values. Scales (spec "units" table): SPEED/SPD 2^-28 step/tick,
// ACC/DEC 2^-40 step/tick², MAX_SPEED 2^-18 step/tick, MIN_SPEED 2^-24 step/tick,
// FS_SPD (x + 0.5)·2^-18 step/tick; one tick = 250 ns. INT_SPEED's scale is a CONFLICT
// in the sources, so it is shown without a unit.
#include "daisychain/explain.hpp"

#include <cmath>
#include <cstdio>

#include "core/commands.hpp"
#include "core/status.hpp"
#include "core/tick.hpp"

namespace l6470emu {
namespace {

constexpr double kTicksPerS = static_cast<double>(kTicksPerSecond);

/// 4 significant digits, no exponent: 2008, 250.0, 15.26, 0.2384.
std::string quantity(double v, const char* unit) {
  const double a = std::fabs(v);
  const int decimals = a >= 1000 ? 0 : a >= 100 ? 1 : a >= 10 ? 2 : a >= 1 ? 3 : 4;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f %s", decimals, v, unit);
  return buf;
}

std::string speed(double per_tick) { return quantity(per_tick * kTicksPerS, "step/s"); }

const char* dir_name(bool forward) { return forward ? "FWD" : "REV"; }

}  // namespace

std::string hex_value(std::uint32_t value, unsigned bits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", static_cast<int>((bits + 3) / 4), value);
  return buf;
}

std::string opcode_name(std::uint8_t opcode, const Variant& table) {
  const Opcode& op = table.opcodes[opcode];
  const Opcode raw = classify_opcode(opcode);
  switch (op.command) {
    case Command::SetParam:
    case Command::GetParam:
      return std::string(to_string(op.command)) + "(" + std::string(table.at_address(op.param)->name) + ")";
    case Command::Run:
    case Command::Move:
    case Command::GoTo_DIR:
    case Command::StepClock:
      return std::string(to_string(op.command)) + "(" + dir_name(op.dir) + ")";
    case Command::GoUntil:
    case Command::ReleaseSW:
      return std::string(to_string(op.command)) + "(" + (op.act ? "ACT=1, " : "ACT=0, ") + dir_name(op.dir) + ")";
    case Command::Reserved:
      return "RESERVED " + hex_value(opcode, 8);
    case Command::Unknown: {
      if (raw.command == Command::SetParam || raw.command == Command::GetParam)
        return std::string(to_string(raw.command)) + "(" + hex_value(raw.param, 8) + ", no such register)";
      // A command of the parts with a motion engine sent to one without (the L6474): say which.
      if (raw.command != Command::Unknown && raw.command != Command::Reserved)
        return "unknown opcode " + hex_value(opcode, 8) + " (" + opcode_name(opcode, l6470()) + " on the others)";
      return "unknown opcode " + hex_value(opcode, 8);
    }
    default:
      return std::string(to_string(op.command));
  }
}

std::string describe_value(const RegisterInfo& r, std::uint32_t v, const StatusLayout& layout) {
  std::string s = hex_value(v, r.bits);
  switch (r.id) {
    case Reg::ABS_POS:
    case Reg::MARK:
      return s + " = " + std::to_string(sign_extend(v, r.bits)) + " microsteps";
    case Reg::EL_POS:
      return s + " = step " + std::to_string((v >> 7) & 3u) + ", microstep " + std::to_string(v & 0x7Fu);
    case Reg::SPEED:
      return s + " = " + speed(std::ldexp(static_cast<double>(v), -28));
    case Reg::ACC:
    case Reg::DEC:
      return s + " = " + quantity(std::ldexp(static_cast<double>(v), -40) * kTicksPerS * kTicksPerS, "step/s²");
    case Reg::MAX_SPEED:
      return s + " = " + speed(std::ldexp(static_cast<double>(v), -18));
    case Reg::MIN_SPEED:
      return s + " = " + speed(std::ldexp(static_cast<double>(v & 0xFFFu), -24)) + ((v & 0x1000u) ? ", LSPD_OPT" : "");
    case Reg::FS_SPD:
      return s + " = " + speed(std::ldexp(static_cast<double>(v & 0x3FFu) + 0.5, -18)) +
             (r.bits > 10 && (v & 0x400u) ? ", BOOST_MODE" : "");
    case Reg::KVAL_HOLD:
    case Reg::KVAL_RUN:
    case Reg::KVAL_ACC:
    case Reg::KVAL_DEC: {
      char buf[32];
      std::snprintf(buf, sizeof buf, " = %.1f %% of VS", v * 100.0 / 256.0);
      return s + buf;
    }
    case Reg::STEP_MODE: {
      const unsigned sel = v & 7u;
      std::string out = s + " = STEP_SEL " + std::to_string(sel) + (sel == 0 ? " (full step)" : " (1/" + std::to_string(1u << sel) + " step)");
      // SYNC_EN drives the BUSY\SYNC pin: a part without one (the L6474, whose STATUS has no
      // BUSY either) gives bits 7:4 no meaning.
      if ((v & 0x80u) && layout.busy >= 0) out += ", SYNC_EN, SYNC_SEL " + std::to_string((v >> 4) & 7u);
      return out;
    }
    case Reg::TVAL: {  // the L6474's: 31.25 mA per step from 31.25 mA
      char buf[32];
      std::snprintf(buf, sizeof buf, " = %g mA", (v + 1) * 31.25);
      return s + buf;
    }
    case Reg::STATUS:
      return s + " [" + describe_status(layout, static_cast<std::uint16_t>(v)) + "]";
    case Reg::CONFIG:
    case Reg::ALARM_EN:
    case Reg::GATECFG1:
    case Reg::GATECFG2:
    case Reg::INT_SPEED:
      return s;
    default:
      return s + " = " + std::to_string(v);
  }
}

std::string describe_command(std::uint8_t opcode, std::uint32_t arg, const Variant& table,
                             const StatusLayout& layout) {
  const Opcode& op = table.opcodes[opcode];
  const std::string name = std::string(to_string(op.command));
  switch (op.command) {
    case Command::SetParam: {
      const RegisterInfo& r = *table.at_address(op.param);
      return name + "(" + std::string(r.name) + ", " + describe_value(r, arg & r.mask(), layout) +
             ((arg & ~r.mask()) ? ", don't-care bits " + hex_value(arg, r.spi_bytes() * 8u) + " sent" : "") + ")";
    }
    case Command::Run:
      return name + "(" + dir_name(op.dir) + ", SPD " + hex_value(arg & 0xFFFFFu, 20) + " = " +
             speed(std::ldexp(static_cast<double>(arg & 0xFFFFFu), -28)) + ")";
    case Command::GoUntil:
      return name + "(" + (op.act ? "ACT=1: ABS_POS to MARK" : "ACT=0: reset ABS_POS") + ", " + dir_name(op.dir) +
             ", SPD " + hex_value(arg & 0xFFFFFu, 20) + " = " + speed(std::ldexp(static_cast<double>(arg & 0xFFFFFu), -28)) +
             ")";
    case Command::ReleaseSW:
      return name + "(" + (op.act ? "ACT=1: ABS_POS to MARK" : "ACT=0: reset ABS_POS") + ", " + dir_name(op.dir) + ")";
    case Command::Move:
      return name + "(" + dir_name(op.dir) + ", " + std::to_string(arg & 0x3FFFFFu) + " microsteps)";
    case Command::GoTo:
      return name + "(ABS_POS " + std::to_string(sign_extend(arg & 0x3FFFFFu, 22)) + ")";
    case Command::GoTo_DIR:
      return name + "(" + dir_name(op.dir) + ", ABS_POS " + std::to_string(sign_extend(arg & 0x3FFFFFu, 22)) + ")";
    case Command::StepClock:
      return name + "(" + dir_name(op.dir) + ")";
    default:
      return opcode_name(opcode, table);
  }
}

std::string describe_answer(std::uint8_t opcode, std::uint32_t value, const Variant& table,
                            const StatusLayout& layout) {
  const Opcode& op = table.opcodes[opcode];
  if (op.command == Command::GetStatus)
    return "GetStatus → " + hex_value(value, 16) + " [" + describe_status(layout, static_cast<std::uint16_t>(value)) + "]";
  const RegisterInfo* r = table.at_address(op.param);
  if (op.command != Command::GetParam || r == nullptr) return opcode_name(opcode, table) + " → " + hex_value(value, 24);
  return "GetParam(" + std::string(r->name) + ") → " + describe_value(*r, value, layout);
}

}  // namespace l6470emu
