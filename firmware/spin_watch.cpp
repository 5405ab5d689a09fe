// start_spin_watch: an ITIMER_PROF tick compares the runtime's entry count with the last one.
#include "firmware/spin_watch.hpp"

#include <signal.h>
#include <sys/time.h>
#include <unistd.h>

#include <cstring>

namespace l6470emu {
namespace {

const volatile std::uint64_t* g_calls = nullptr;
const char* g_message = nullptr;
std::uint64_t g_last = 0;
int g_still = 0;       // ticks in a row with no entry
bool g_said = false;

void on_tick(int) {
  if (g_said || !g_calls) return;
  const std::uint64_t now = *g_calls;
  if (now != g_last) {
    g_last = now;
    g_still = 0;
    return;
  }
  if (++g_still < kSpinWatchSeconds) return;
  g_said = true;
  // write(2) is async-signal-safe; the line is whole in one call.
  const ssize_t ignored = ::write(2, g_message, std::strlen(g_message));
  (void)ignored;
}

}  // namespace

void start_spin_watch(const volatile std::uint64_t* calls, const char* message) {
  struct sigaction old {};
  if (::sigaction(SIGPROF, nullptr, &old) != 0 || old.sa_handler != SIG_DFL) return;  // the program's own
  g_calls = calls;
  g_message = message;
  g_last = *calls;
  struct sigaction sa {};
  sa.sa_handler = on_tick;
  sa.sa_flags = SA_RESTART;
  sigemptyset(&sa.sa_mask);
  if (::sigaction(SIGPROF, &sa, nullptr) != 0) return;
  itimerval every_second{};
  every_second.it_interval.tv_sec = 1;
  every_second.it_value.tv_sec = 1;
  ::setitimer(ITIMER_PROF, &every_second, nullptr);
}

}  // namespace l6470emu
