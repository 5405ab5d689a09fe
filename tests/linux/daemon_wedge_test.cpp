// `l6470emu serve` cannot be wedged by its clients: one that attaches its shared region, leaves
// a packet unread on its socket and dies is reaped like any other, one killed in the middle of a
// long message does not hold the bus for the rest of it, and SIGTERM ends the daemon whatever its
// clients left behind.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <thread>

#include <gtest/gtest.h>

#include "raw_client.hpp"
#include "spi/message.hpp"
#include "spi/trace_native.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

constexpr const char* kChain = "bus=0 cs=0 chips=L6470";

class DaemonWedge : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
  }
};

/// `ctl clients` until it counts `n` clients (ctl itself included), at most ~10 s; the last answer.
std::string wait_for_clients(const ServeDaemon& d, int n) {
  const std::string want = std::to_string(n) + (n == 1 ? " client\n" : " clients\n");
  std::string out;
  for (int i = 0; i < 200; ++i) {
    out = d.ctl({"clients"}).out;
    if (out.rfind(want, 0) == 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return out;
}

TEST_F(DaemonWedge, ClientsThatDieWithAPacketUnreadAreReaped) {
  ServeDaemon d(kChain);
  ASSERT_TRUE(d.ready()) << d.process().out();
  // More dead connections than the daemon serves at once (272 against its 256), from processes
  // of 16 (the most one process may have): each batch must be reaped for the next to be served,
  // and a live client after them all is.
  for (int batch = 0; batch < 17; ++batch) {
    EXPECT_EQ(dead_clients_with_unread_packets(d.socket(), 16), 16) << "batch " << batch;
    const std::string clients = wait_for_clients(d, 1);  // ctl's own connection only
    ASSERT_EQ(clients.rfind("1 client\n", 0), 0u) << "batch " << batch << ": the dead are still listed:\n" << clients;
  }
  const RunResult r = run_program({client("spidev_reader"), "/dev/spidev0.0", "10", "0x01", "0"}, d.env());
  EXPECT_EQ(r.out, "reads=10 torn=0\n") << r.err;
  EXPECT_EQ(d.process().stop(SIGTERM, 10).status, 0);
}

TEST_F(DaemonWedge, SigtermEndsTheDaemonWhateverItsClientsLeftBehind) {
  ServeDaemon d(kChain);
  ASSERT_TRUE(d.ready()) << d.process().out();
  // A live client sleeping on its region's futex, and dead ones whose packets nobody reads.
  Background holder({system_python(), "-c",
                     "import spidev, time\ns = spidev.SpiDev(); s.open(0, 0); s.xfer2([0])\n"
                     "print('done', flush=True)\ntime.sleep(60)\n"},
                    d.env());
  for (int i = 0; i < 1000 && holder.out().find("done") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(dead_clients_with_unread_packets(d.socket(), 8), 8);
  const RunResult r = d.process().stop(SIGTERM, 10);
  EXPECT_EQ(r.status, 0) << "the daemon did not end within 10 s of SIGTERM (status 137: killed)\n" << r.err;
  EXPECT_NE(r.out.find("l6470emu serve: stopping"), std::string::npos) << r.out;
}

TEST_F(DaemonWedge, ALiveClientNeverWaitsOutTheBusTimeOfADeadOne) {
  const std::string trace = temp_socket_path("dead-bus") + ".trace";
  ServeDaemon d(kChain, {"--record", trace, "--log", "off"});
  ASSERT_TRUE(d.ready()) << d.process().out();
  // 4096 NOPs at the controller's slowest clock: 8.6 s of bus time in one message.
  Background slow({system_python(), "-c",
                   "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
                   "print('start', flush=True)\ns.xfer2([0] * 4096, 3815)\nprint('finished')\n"},
                  d.env());
  for (int i = 0; i < 1000 && slow.out().find("start") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(2000));  // in the middle of its message (8.6 s, started well before)
  EXPECT_EQ(slow.stop(SIGKILL).out, "start\n");
  const RunResult fast = run_program(
      {system_python(), "-c",
       "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\nprint(s.xfer2([0xD0, 0, 0]))\n"},
      d.env());
  EXPECT_EQ(fast.status, 0) << fast.err;
  EXPECT_EQ(d.process().stop(SIGTERM).status, 0);
  // The recording says when each message had the bus: the dead one's frame was cut short where
  // its client died, and the live one's began right after, long before the dead one would have ended.
  std::ifstream in(trace);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const Trace t = read_native_trace(text, trace);
  std::vector<TraceEvent> frames;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i].kind == TraceEventKind::frame) frames.push_back(t[i]);
  ASSERT_EQ(frames.size(), 2u) << text.substr(0, 2000);
  const Tick full = 4096 * transfer_ticks(1, 3815);
  EXPECT_GT(frames[0].mosi.size(), 0u);
  EXPECT_LT(frames[0].mosi.size(), 4096u) << "the dead client's message was clocked to its end";
  EXPECT_LT(frames[0].duration, full);
  EXPECT_LT(frames[1].tick, frames[0].tick + full) << "the live client waited for the dead one's bus time";
  EXPECT_EQ(frames[1].mosi.size(), 3u);
  unlink(trace.c_str());
}

}  // namespace
}  // namespace l6470emu::test
