// STATUS encoding for any layout: active-high and active-low fields placed by the variant's table.
#include "core/status.hpp"

namespace l6470emu {
namespace {

void put(std::uint16_t& word, std::int8_t bit, bool level) {
  if (bit >= 0 && level) word = static_cast<std::uint16_t>(word | (1u << bit));
}

bool get(std::uint16_t word, std::int8_t bit) { return bit >= 0 && ((word >> bit) & 1u) != 0; }

}  // namespace

std::uint16_t encode_live(const StatusLayout& l, const LiveStatus& live) {
  std::uint16_t w = 0;
  put(w, l.hiz, live.hiz);
  put(w, l.busy, !live.busy);
  put(w, l.sw_f, live.sw_closed);
  put(w, l.dir, live.forward);
  if (l.mot_status >= 0) w = static_cast<std::uint16_t>(w | (static_cast<unsigned>(live.mot) << l.mot_status));
  put(w, l.sck_mod, live.step_clock);
  return w;
}

std::uint16_t encode_latched(const StatusLayout& l, const AlarmFlags& a) {
  std::uint16_t w = l.unused_ones;
  put(w, l.sw_evn, a.sw_evn);
  put(w, l.notperf_cmd, a.notperf_cmd);
  put(w, l.wrong_cmd, a.wrong_cmd);
  put(w, l.uvlo, !a.uvlo);
  put(w, l.uvlo_adc, !a.uvlo_adc);
  put(w, l.th_wrn, a.thermal < Thermal::warning);
  put(w, l.th_sd, a.thermal < Thermal::bridge_shutdown);
  if (l.th_status >= 0) w = static_cast<std::uint16_t>(w | (static_cast<unsigned>(a.thermal) << l.th_status));
  put(w, l.ocd, !a.ocd);
  put(w, l.step_loss_a, !a.stall_a);
  put(w, l.step_loss_b, !a.stall_b);
  return w;
}

std::string describe_status(const StatusLayout& l, std::uint16_t s) {
  std::string out;
  auto add = [&](const char* name) {
    if (!out.empty()) out += ' ';
    out += name;
  };
  if (get(s, l.hiz)) add("HiZ");
  if (l.busy >= 0 && !get(s, l.busy)) add("BUSY");
  if (get(s, l.sw_f)) add("SW_F");
  if (get(s, l.sw_evn)) add("SW_EVN");
  add(get(s, l.dir) ? "FWD" : "REV");
  if (l.mot_status >= 0) {
    static constexpr const char* kMot[] = {"STOPPED", "ACC", "DEC", "CONST"};
    add(kMot[(s >> l.mot_status) & 3u]);
  }
  if (l.notperf_cmd == l.wrong_cmd) {
    if (get(s, l.wrong_cmd)) add("CMD_ERROR");
  } else {
    if (get(s, l.notperf_cmd)) add("NOTPERF_CMD");
    if (get(s, l.wrong_cmd)) add("WRONG_CMD");
  }
  if (l.uvlo >= 0 && !get(s, l.uvlo)) add("UVLO");
  if (l.uvlo_adc >= 0 && !get(s, l.uvlo_adc)) add("UVLO_ADC");
  if (l.th_wrn >= 0 && !get(s, l.th_wrn)) add("TH_WRN");
  if (l.th_sd >= 0 && !get(s, l.th_sd)) add("TH_SD");
  if (l.th_status >= 0) {
    static constexpr const char* kTh[] = {nullptr, "TH_WARNING", "TH_BRIDGE_SHUTDOWN", "TH_DEVICE_SHUTDOWN"};
    if (const auto t = (s >> l.th_status) & 3u; t != 0) add(kTh[t]);
  }
  if (l.ocd >= 0 && !get(s, l.ocd)) add("OCD");
  if (l.step_loss_a >= 0 && !get(s, l.step_loss_a)) add(std::string(l.step_loss_a_name).c_str());
  if (l.step_loss_b >= 0 && !get(s, l.step_loss_b)) add(std::string(l.step_loss_b_name).c_str());
  if (get(s, l.sck_mod)) add("SCK_MOD");
  return out;
}

}  // namespace l6470emu
