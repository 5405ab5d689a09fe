// A fault soak of `l6470emu serve` (bounded in time): 50 preload clients read through one
// daemon while some are killed with SIGKILL mid-message, others throw garbage at the socket,
// others die with a packet left unread on their socket, and slow-bus clients (SCK at the
// controller's slowest, each message longer than the daemon's 10 ms slice) share the bus, some
// killed mid-message. The daemon keeps serving and reaps every dead client, the survivors'
// answers stay exact, and the recording made throughout replays clean after the daemon is
// stopped with SIGTERM, and after SIGKILL.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "raw_client.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

constexpr int kClients = 50;
constexpr int kKilled = 10;
constexpr int kGarbage = 4;
constexpr const char* kReads = "1500";
constexpr int kSlow = 4;        // slow-bus clients, half of them killed
constexpr int kDeadBatches = 3;  // processes dying with 4 connections' packets unread

/// `ctl clients` until it counts only ctl itself, at most ~10 s; the last answer.
std::string wait_until_only_ctl(const ServeDaemon& d) {
  std::string out;
  for (int i = 0; i < 200; ++i) {
    out = d.ctl({"clients"}).out;
    if (out.rfind("1 client\n", 0) == 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return out;
}

class DaemonSoak : public ::testing::TestWithParam<int> {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
  }
};

TEST_P(DaemonSoak, SurvivorsStayExactAndTheRecordingReplaysClean) {
  const int stop_signal = GetParam();
  const std::string trace = temp_socket_path("soak") + ".trace";
  ServeDaemon d("bus=0 cs=0 chips=L6470", {"--record", trace, "--log", "off"});
  ASSERT_TRUE(d.ready()) << d.process().out();
  ASSERT_EQ(run_program({system_python(), script("set_mark.py"), "0", "0", "0x12345"}, d.env()).status, 0);

  std::vector<std::unique_ptr<Background>> readers, garbage;
  for (int i = 0; i < kClients; ++i)
    readers.push_back(std::make_unique<Background>(
        std::vector<std::string>{client("spidev_reader"), "/dev/spidev0.0", kReads, "0x03", "0x12345"}, d.env()));
  for (int i = 0; i < kGarbage; ++i)
    garbage.push_back(std::make_unique<Background>(
        std::vector<std::string>{system_python(), script("garbage_client.py"), d.socket(), std::to_string(i), "4"}));
  // Messages of 8 NOPs at 3815 Hz: 16.8 ms of bus each, longer than a slice (the daemon clocks
  // them a slice at a time, giving up a killed client's at the next slice), 30 per client.
  std::vector<std::unique_ptr<Background>> slow;
  for (int i = 0; i < kSlow; ++i)
    slow.push_back(std::make_unique<Background>(
        std::vector<std::string>{system_python(), "-c",
                                 "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
                                 "for _ in range(30): s.xfer2([0] * 8, 3815)\nprint('slow=done')\n"},
        d.env()));
  std::this_thread::sleep_for(std::chrono::milliseconds(350));
  for (int i = 0; i < kDeadBatches; ++i) EXPECT_EQ(dead_clients_with_unread_packets(d.socket(), 4), 4);
  std::this_thread::sleep_for(std::chrono::milliseconds(350));
  for (int i = 0; i < kKilled; ++i) readers[static_cast<std::size_t>(i * (kClients / kKilled))]->stop(SIGKILL);
  for (int i = 0; i < kSlow / 2; ++i) slow[static_cast<std::size_t>(i)]->stop(SIGKILL);

  int survivors = 0;
  for (int i = 0; i < kClients; ++i) {
    if (i % (kClients / kKilled) == 0 && i / (kClients / kKilled) < kKilled) continue;
    const RunResult r = readers[static_cast<std::size_t>(i)]->wait(120);
    EXPECT_EQ(r.out, std::string("reads=") + kReads + " torn=0\n") << "client " << i << ": " << r.err;
    ++survivors;
  }
  EXPECT_EQ(survivors, kClients - kKilled);
  for (auto& g : garbage) {
    const RunResult r = g->wait(30);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out.rfind("sent=", 0), 0u) << r.out;
  }
  for (int i = kSlow / 2; i < kSlow; ++i) {
    const RunResult r = slow[static_cast<std::size_t>(i)]->wait(60);
    EXPECT_EQ(r.out, "slow=done\n") << r.err;
  }
  // Every client is gone, the killed, the dead with packets unread and the finished alike.
  const std::string clients = wait_until_only_ctl(d);
  EXPECT_EQ(clients.rfind("1 client\n", 0), 0u) << clients;
  // Still serving, and the killed clients' files were released.
  const RunResult after = run_program({client("spidev_reader"), "/dev/spidev0.0", "10", "0x03", "0x12345"}, d.env());
  EXPECT_EQ(after.out, "reads=10 torn=0\n") << after.err;
  // (A file is released when the daemon sees its last descriptor close: at once, but on its own thread.)
  std::string dump;
  for (int i = 0; i < 100; ++i) {
    dump = d.ctl({"dump"}).out;
    if (dump.find("spidev0.0: 0 open") != std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_NE(dump.find("spidev0.0: 0 open"), std::string::npos) << dump.substr(dump.rfind("spidev0.0:"));

  const RunResult stopped = d.process().stop(stop_signal, 30);
  if (stop_signal == SIGTERM) {
    EXPECT_EQ(stopped.status, 0) << stopped.err;
  }
  unlink(d.socket().c_str());
  const RunResult replay = run_program({l6470emu_program(), "replay", trace}, {}, 120);
  EXPECT_EQ(replay.status, 0) << replay.out << replay.err;
  EXPECT_NE(replay.out.find(": matched"), std::string::npos) << replay.out;
  unlink(trace.c_str());
}

// The campaign's faults raised through ctl, again and again, with interface coverage collected,
// while hostile clients come and go: the daemon serves on, reaps every client, writes a coverage
// file that reads back with the faults it raised, and its recording (every fault in it) replays.
TEST(DaemonSoakWithFaults, EveryCampaignFaultRaisedUnderHostileClientsLeavesADaemonServingACoverageFileAndARecording) {
  const std::string why = missing_prerequisites();
  if (!why.empty()) GTEST_SKIP() << why;
  const std::string base = temp_socket_path("faultsoak");
  const std::string trace = base + ".trace", coverage = base + ".coverage.json";
  ServeDaemon d("bus=0 cs=0 chips=L6470", {"--record", trace, "--coverage", coverage, "--log", "off"});
  ASSERT_TRUE(d.ready()) << d.process().out();
  std::vector<std::unique_ptr<Background>> readers, garbage;
  for (int i = 0; i < 20; ++i)  // their answers are not exact here: the faults change them
    readers.push_back(std::make_unique<Background>(
        std::vector<std::string>{client("spidev_reader"), "/dev/spidev0.0", "400", "0x19", "0"}, d.env()));
  for (int i = 0; i < 2; ++i)
    garbage.push_back(std::make_unique<Background>(
        std::vector<std::string>{system_python(), script("garbage_client.py"), d.socket(), std::to_string(i), "4"}));
  const std::vector<std::vector<std::string>> faults{
      {"fault", "ocd", "on", "--chip", "0"},           {"fault", "ocd", "off", "--chip", "0"},
      {"fault", "thermal", "warning", "--chip", "0"},  {"fault", "thermal", "device-shutdown", "--chip", "0"},
      {"fault", "thermal", "normal", "--chip", "0"},   {"fault", "uvlo", "on", "--chip", "0"},
      {"fault", "uvlo", "off", "--chip", "0"},         {"fault", "stall-a", "on", "--chip", "0"},
      {"fault", "stall-a", "off", "--chip", "0"},      {"fault", "stall-b", "on", "--chip", "0"},
      {"fault", "stall-b", "off", "--chip", "0"},      {"fault", "reset", "--chip", "0"},
      {"fault", "lost-frame", "--chip", "0"},          {"fault", "miso-flip", "5", "--chip", "0"},
      {"sw", "closed", "--chip", "0"},                 {"sw", "open", "--chip", "0"},
  };
  for (int round = 0; round < 3; ++round) {
    for (const auto& f : faults) {
      const RunResult r = d.ctl(f);
      EXPECT_EQ(r.status, 0) << f[1] << ": " << r.out << r.err;
    }
    if (round == 1)
      for (int i = 0; i < 5; ++i) readers[static_cast<std::size_t>(i * 4)]->stop(SIGKILL);
    EXPECT_EQ(dead_clients_with_unread_packets(d.socket(), 4), 4);
  }
  for (int i = 0; i < 20; ++i) {
    if (i % 4 == 0) continue;
    const RunResult r = readers[static_cast<std::size_t>(i)]->wait(120);
    EXPECT_EQ(r.out.rfind("reads=400 ", 0), 0u) << "client " << i << ": " << r.out << r.err;
  }
  for (auto& g : garbage) EXPECT_EQ(g->wait(30).status, 0);
  const std::string clients = wait_until_only_ctl(d);
  EXPECT_EQ(clients.rfind("1 client\n", 0), 0u) << clients;
  const RunResult status = d.ctl({"status", "--chip", "0"});
  EXPECT_EQ(status.status, 0) << status.err;
  const RunResult stopped = d.process().stop(SIGTERM, 30);
  EXPECT_EQ(stopped.status, 0) << stopped.err;
  unlink(d.socket().c_str());
  const RunResult report = run_program({l6470emu_program(), "coverage", "report", "--format", "json", coverage}, {}, 60);
  ASSERT_EQ(report.status, 0) << report.out << report.err;
  const auto raised = nlohmann::json::parse(report.out)["variants"]["L6470"]["categories"]["flags raised"]["hit points"];
  for (const char* flag : {"OCD", "TH_SD", "UVLO", "STEP_LOSS_A", "STEP_LOSS_B"})
    EXPECT_NE(std::find(raised.begin(), raised.end(), flag), raised.end()) << flag << " was not raised: " << raised;
  const RunResult replay = run_program({l6470emu_program(), "replay", trace}, {}, 120);
  EXPECT_EQ(replay.status, 0) << replay.out << replay.err;
  EXPECT_NE(replay.out.find(": matched"), std::string::npos) << replay.out;
  unlink(trace.c_str());
  unlink(coverage.c_str());
}

INSTANTIATE_TEST_SUITE_P(StoppedBySigtermAndBySigkill, DaemonSoak, ::testing::Values(SIGTERM, SIGKILL),
                         [](const auto& info) { return info.param == SIGTERM ? "Sigterm" : "Sigkill"; });

}  // namespace
}  // namespace l6470emu::test
