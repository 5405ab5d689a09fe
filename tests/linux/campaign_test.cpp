// `l6470emu campaign` end to end: real drivers (tests/linux/clients/campaign_driver.c) under the
// preload, each way a driver meets a fault given its verdict, the JSON the same every time and
// the same from shards, reproducers that reproduce, and bad input refused before anything runs.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "run_program.hpp"

namespace l6470emu::test {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

class Campaign : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
    dir_ = fs::temp_directory_path() / ("l6470emu-campaign-test-" + std::to_string(getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  static std::string read(const std::string& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // `l6470emu campaign ARGS -- campaign_driver MODE` on one L6470.
  static RunResult campaign(std::vector<std::string> args, const std::string& mode) {
    std::vector<std::string> argv{l6470emu_program(), "campaign", "--chain", "chips=L6470 check=warn"};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.insert(argv.end(), {"--", client("campaign_driver"), mode});
    return run_program(argv, {}, 120);
  }
  // The rerun of `fault` at `point` in a campaign's JSON.
  static Json rerun(const Json& report, const std::string& fault, const std::string& point) {
    for (const Json& r : report["reruns"])
      if (r["fault"] == fault && r["point"]["name"] == point) return r;
    ADD_FAILURE() << "no rerun of " << fault << " at " << point;
    return Json::object();
  }
  fs::path dir_;
};

TEST_F(Campaign, ADriverThatChecksStatusWhileItPollsDetectsAnOvercurrentAndSurvivesAThermalWarning) {
  const RunResult r = campaign({"--faults", "ocd,thermal_warning", "--json", path("c.json")}, "careful");
  EXPECT_EQ(r.status, 0) << r.err;
  const Json j = Json::parse(read(path("c.json")));
  EXPECT_EQ(rerun(j, "ocd", "during_motion")["verdict"], "detected");
  EXPECT_EQ(rerun(j, "ocd", "during_motion")["flag_read"], true);
  EXPECT_EQ(rerun(j, "ocd", "during_motion")["exit"], 6);
  EXPECT_EQ(rerun(j, "thermal_warning", "during_motion")["verdict"], "survived");
  EXPECT_EQ(j["oracle"], "clean_run");
  EXPECT_EQ(j["complete"], true);
  EXPECT_EQ(j["summary"]["silent_failure"], 0);
  EXPECT_NE(r.out.find("reruns: "), std::string::npos) << r.out;
}

TEST_F(Campaign, ADriverThatIgnoresEveryFlagFailsSilentlyAndItsReproducerFailsTheSameWay) {
  const RunResult r = campaign({"--faults", "ocd,stby_pulse", "--json", path("c.json")}, "careless");
  EXPECT_EQ(r.status, 1) << r.err;
  const Json j = Json::parse(read(path("c.json")));
  for (const std::string fault : {"ocd", "stby_pulse"}) {
    const Json x = rerun(j, fault, "during_motion");
    EXPECT_EQ(x["verdict"], "silent_failure") << x;
    EXPECT_EQ(x["exit"], 1) << x;
    ASSERT_TRUE(x["reproducer"].is_string()) << x;
    EXPECT_TRUE(fs::exists(x["reproducer"].get<std::string>()));
    EXPECT_EQ(x["first_failure"]["where"], "the clean run's end") << x;
    // The printed command runs that rerun alone and fails the same way.
    std::string cmd = x["command"];
    ASSERT_EQ(cmd.rfind("l6470emu run ", 0), 0u) << cmd;
    const RunResult again = run_program({"/bin/sh", "-c", l6470emu_program() + cmd.substr(8)}, {}, 60);
    EXPECT_EQ(again.status, 1) << again.err;
    EXPECT_NE(again.err.find("FAILED"), std::string::npos) << again.err;
  }
  // A reset by the pin left the motor elsewhere: the driver reported success all the same.
  EXPECT_NE(r.out.find("silent_failure: stby_pulse"), std::string::npos) << r.out;
}

TEST_F(Campaign, ADriverThatWaitsForAFlagThatNeverClearsHangsAndOneThatAbortsCrashesAndOneThatWaitsDeadlocks) {
  const RunResult stuck = campaign({"--faults", "ocd", "--json", path("stuck.json")}, "stuck");
  EXPECT_EQ(stuck.status, 1) << stuck.err;
  EXPECT_EQ(rerun(Json::parse(read(path("stuck.json"))), "ocd", "during_motion")["verdict"], "hang");
  const RunResult crash = campaign({"--faults", "ocd", "--json", path("crash.json")}, "crash");
  EXPECT_EQ(crash.status, 1) << crash.err;
  EXPECT_EQ(rerun(Json::parse(read(path("crash.json"))), "ocd", "during_motion")["verdict"], "crash");
  const RunResult dead = campaign({"--faults", "ocd", "--json", path("dead.json")}, "deadlock");
  EXPECT_EQ(dead.status, 1) << dead.err;
  EXPECT_EQ(rerun(Json::parse(read(path("dead.json"))), "ocd", "during_motion")["verdict"], "deadlock");
}

TEST_F(Campaign, ABrownOutAndALostFrameAreSeenByACarefulDriverAndMissedByACarelessOne) {
  // A reset right after configuring goes unseen even so: the driver's settings are lost.
  ASSERT_EQ(campaign({"--faults", "reset,lost_frame,miso_flip", "--json", path("careful.json")}, "careful").status, 1);
  const Json careful = Json::parse(read(path("careful.json")));
  EXPECT_EQ(rerun(careful, "reset", "during_motion")["verdict"], "detected");
  EXPECT_EQ(rerun(careful, "reset", "during_motion")["flag_read"], true);
  EXPECT_EQ(rerun(careful, "reset", "after_config")["verdict"], "silent_failure");
  // The GetStatus opcode after the Move never reaches the chip: the driver reads 0x0000, OCD.
  EXPECT_EQ(rerun(careful, "lost_frame", "at_Move")["verdict"], "detected");
  EXPECT_TRUE(rerun(careful, "lost_frame", "at_Move")["flag_read"].is_null());
  EXPECT_EQ(rerun(careful, "miso_flip", "during_motion")["verdict"], "survived");
  EXPECT_EQ(campaign({"--faults", "reset", "--json", path("careless.json")}, "careless").status, 1);
  const Json careless = Json::parse(read(path("careless.json")));
  EXPECT_EQ(rerun(careless, "reset", "during_motion")["verdict"], "silent_failure");
  // GoTo 1000 still ends at 1000 after the position was lost; the settings it wrote did not survive.
  EXPECT_EQ(rerun(careless, "reset", "during_motion")["first_failure"]["what"], "ACC");
}

TEST_F(Campaign, ADriverThatWatchesTheFlagPinReadsTheFaultWithoutAskingForStatus) {
  // python3-libgpiod: BUSY and FLAG as lines; STATUS is read once, before the fault can come.
  // Move out, watch the pins while it runs, GoTo back (its last command: the points lie before it).
  std::ofstream(path("pins.py")) << R"(import sys, time
import gpiod, spidev
chip = gpiod.Chip("gpiochip0")
busy, flag = chip.get_line(0), chip.get_line(1)
for line in (busy, flag):
    line.request(consumer="campaign", type=gpiod.LINE_REQ_DIR_IN)
s = spidev.SpiDev(); s.open(0, 0); s.mode = 3
x = lambda *bs: [s.xfer2([b])[0] for b in bs]
x(0xD0, 0, 0)
x(0x41, 0x00, 0x10, 0x00)
while busy.get_value() == 0:
    if flag.get_value() == 0:
        sys.exit(1)
    time.sleep(0.005)
x(0x60, 0, 0, 0)
)";
  const RunResult r = run_program({l6470emu_program(), "campaign", "--chain", "bus=0 cs=0 chips=L6470 check=warn", "--faults",
                                   "thermal_warning,ocd", "--json", path("c.json"), "--", system_python(), path("pins.py")},
                                  {}, 120);
  const Json j = Json::parse(read(path("c.json")));
  const Json warned = rerun(j, "thermal_warning", "during_motion");
  EXPECT_EQ(warned["verdict"], "detected") << r.err;
  EXPECT_EQ(warned["flag_read"], true) << warned;
  // An overcurrent stops the motor: BUSY rises and the loop ends before it looks at FLAG again.
  const Json stopped = rerun(j, "ocd", "during_motion");
  EXPECT_EQ(stopped["verdict"], "silent_failure") << stopped;
  EXPECT_EQ(r.status, 1) << r.err;
}

TEST_F(Campaign, TheSameCampaignTwiceGivesTheSameJsonAndThreeShardsMergeIntoIt) {
  const std::vector<std::string> args{"--faults", "ocd,uvlo,sw_close", "--json", path("c.json")};
  const int status = campaign(args, "careful").status;
  ASSERT_TRUE(status == 0 || status == 1) << status;
  const std::string first = read(path("c.json"));
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = args;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  ASSERT_EQ(campaign(with({"-j", "1"}), "careful").status, status);
  EXPECT_EQ(read(path("c.json")), first);
  std::vector<std::string> merge{l6470emu_program(), "campaign", "merge"};
  for (int k = 1; k <= 3; ++k) {
    ASSERT_NE(campaign(with({"--shard", std::to_string(k) + "/3"}), "careful").status, 2);
    const Json shard = Json::parse(read(path("c.json")));
    EXPECT_EQ(shard["shard"], std::to_string(k) + "/3");
    fs::rename(path("c.json"), path("shard" + std::to_string(k) + ".json"));
    merge.push_back(path("shard" + std::to_string(k) + ".json"));
  }
  merge.insert(merge.end(), {"-o", path("merged.json")});
  const RunResult m = run_program(merge);
  EXPECT_EQ(m.status, status) << m.err;
  EXPECT_EQ(read(path("merged.json")), first);
}

TEST_F(Campaign, ListPrintsTheFaultsAndPointsOfTheCleanRunWithoutRerunning) {
  const RunResult r = campaign({"--list"}, "careful");
  EXPECT_EQ(r.status, 0) << r.err;
  for (const char* word : {"after_config at ", "at_Move at ", "at_GoTo at ", "during_motion at ", "before_last_command at ",
                           "faults: ocd thermal_warning", " reruns (oracle: the clean run's end state)"})
    EXPECT_NE(r.out.find(word), std::string::npos) << word << "\n" << r.out;
  EXPECT_EQ(r.out.find("uvlo_adc"), std::string::npos) << "an L6470 has no ADC undervoltage\n" << r.out;
}

TEST_F(Campaign, TheJUnitReportIsWellFormedXmlWithACasePerFaultAndChip) {
  const RunResult r = campaign({"--faults", "ocd,thermal_warning", "--junit", path("c.xml")}, "careless");
  EXPECT_EQ(r.status, 1) << r.err;
  const RunResult parsed = run_program(
      {system_python(), "-c",
       "import sys, xml.etree.ElementTree as E; t = E.parse(sys.argv[1]); "
       "print(sorted((c.get('name'), c.find('failure') is not None) for c in t.iter('testcase')))",
       path("c.xml")});
  EXPECT_EQ(parsed.status, 0) << parsed.err;
  EXPECT_EQ(parsed.out, "[('ocd spidev0.0 chip 0', True), ('thermal_warning spidev0.0 chip 0', False)]\n") << parsed.out;
}

TEST_F(Campaign, ACleanRunThatFailsEndsTheCampaignWithRunsOwnStatus) {
  std::ofstream(path("s.yaml")) << "steps:\n  - at: end\n    expect: {register: ABS_POS, value: 12345}\n";
  const RunResult r = campaign({"--scenario", path("s.yaml"), "--json", path("c.json")}, "careful");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("the clean run did not pass (run's exit 1); no fault was injected"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("c.json")));
}

TEST_F(Campaign, AProgramThatNeverSpeaksToTheChipIsNoPass) {
  const RunResult r = run_program({l6470emu_program(), "campaign", "--chain", "chips=L6470", "--", "/bin/true"}, {}, 60);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("sent no command to any chip"), std::string::npos) << r.err;
}

TEST_F(Campaign, BadInputIsOneLineAndStatusTwoAndNothingRuns) {
  std::ofstream(path("board")) << "chips=L6470\n";
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {{"--faults", "ocdd"}, "'ocdd' is not a fault (did you mean ocd?)"},
      {{"--faults", "uvlo_adc"}, "uvlo_adc cannot be raised on this board: L6470 has no ADC undervoltage"},
      {{"--faults", ""}, "'' is not a fault"},
      {{"--shard", "4/3"}, "--shard '4/3' is not K/N"},
      {{"--shard", "0/3"}, "--shard '0/3' is not K/N"},
      {{"--points", "every-comand"}, "(did you mean every-command?)"},
      {{"--json", "/proc/version"}, "cannot write '/proc/version'"},
      {{"--json", "/no/such/dir/c.json"}, "cannot write '/no/such/dir/c.json'"},
      {{"--junit", client("campaign_driver")}, "an output never overwrites an input"},
      {{"--fail-on", "silent"}, "'silent' is not a verdict"},
      {{"--chips", "1"}, "--chips: the board has no chip '1'"},
  };
  for (const auto& [args, said] : cases) {
    const RunResult r = campaign(args, "careful");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find(said), std::string::npos) << said << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.find("the clean run"), std::string::npos) << r.err;
  }
}

TEST_F(Campaign, SnapshotsWriteTheSameJsonAsRerunsFromTheBeginningAndSayHowManyWereForked) {
  // A Python driver (python3-spidev): "one" is single-threaded, "threads" has a second thread at
  // every injection tick (no rerun can be forked), "fifo" blocks on a FIFO nobody opens when it
  // sees a fault (the wall-clock limit ends it: hang).
  std::ofstream(path("driver.py")) << R"(import os, sys, threading, time, spidev
mode = sys.argv[1]
if mode == "threads":
    threading.Thread(target=threading.Event().wait, daemon=True).start()
s = spidev.SpiDev(); s.open(0, 0); s.mode = 3
x = lambda *bs: [s.xfer2([b])[0] for b in bs]
def status():
    r = x(0xD0, 0, 0)
    return (r[1] << 8) | r[2]
x(0x05, 0x00, 0x40); x(0x06, 0x00, 0x40); x(0x07, 0x00, 0x30)
status()
x(0x41, 0x00, 0x0F, 0xA0)
while True:
    st = status()
    if not st & 0x1000 or not st & 0x0200:
        if mode == "fifo":
            fifo = "%s/fifo.%d" % (sys.argv[2], os.getpid())
            os.mkfifo(fifo)
            open(fifo).read()
        sys.exit(1)
    if st & 0x0002:
        break
    time.sleep(0.005)
x(0x60, 0x00, 0x03, 0xE8)
while not status() & 0x0002:
    time.sleep(0.005)
)";
  struct Case {
    std::vector<std::string> args, program;
    std::size_t forked_of_all;  // 1: every rerun forked; 0: none
  };
  const std::string c = client("campaign_driver"), py = path("driver.py");
  const std::vector<Case> cases{
      {{"--faults", "ocd,uvlo,reset,lost_frame,miso_flip"}, {c, "careful"}, 1},
      {{"--faults", "ocd"}, {c, "stuck"}, 1},
      {{"--faults", "ocd"}, {c, "crash"}, 1},
      {{"--faults", "ocd"}, {c, "deadlock"}, 1},
      {{"--faults", "ocd,reset"}, {system_python(), py, "one"}, 1},
      {{"--faults", "ocd"}, {system_python(), py, "threads"}, 0},
      {{"--faults", "ocd", "--at", "during_motion", "--wall-timeout", "4"}, {system_python(), py, "fifo", dir_.string()}, 1},
  };
  for (const Case& k : cases) {
    std::string json[2];
    int status[2] = {0, 0};
    for (const int snapshots : {1, 0}) {
      fs::create_directories(path(snapshots ? "yes" : "no"));
      std::vector<std::string> argv{l6470emu_program(), "campaign", "--chain", "chips=L6470 check=warn", "--snapshots",
                                    snapshots ? "yes" : "no", "--json", path(snapshots ? "yes/c.json" : "no/c.json")};
      argv.insert(argv.end(), k.args.begin(), k.args.end());
      argv.push_back("--");
      argv.insert(argv.end(), k.program.begin(), k.program.end());
      const RunResult r = run_program(argv, {}, 120);
      status[snapshots] = r.status;
      json[snapshots] = read(path(snapshots ? "yes/c.json" : "no/c.json"));
      for (std::size_t at; (at = json[snapshots].find(snapshots ? "/yes/" : "/no/")) != std::string::npos;)
        json[snapshots].replace(at, snapshots ? 5 : 4, "/X/");
      if (snapshots) {
        const std::size_t total = Json::parse(read(path("yes/c.json")))["total"];
        ASSERT_GT(total, 0u);
        const std::string said = std::to_string(k.forked_of_all * total) + " of " + std::to_string(total) + " reruns forked from snapshots";
        EXPECT_NE(r.err.find(said), std::string::npos) << k.program.back() << ": " << r.err;
      }
    }
    EXPECT_EQ(status[1], status[0]) << k.program.back();
    EXPECT_EQ(json[1], json[0]) << k.program.back();
  }
  // The verdicts a snapshot's child can come to, as the plain reruns came to them.
  EXPECT_EQ(rerun(Json::parse(read(path("yes/c.json"))), "ocd", "during_motion")["verdict"], "hang");
}

TEST_F(Campaign, WhatARerunEndedAtItsWallClockLimitLeftRunningInASessionOfItsOwnIsEndedToo) {
  // The rerun starts a shell in a session of its own (setsid: no signal to the rerun's process
  // group reaches it), then blocks where virtual time cannot see; the wall-clock limit ends it.
  const std::string script = path("driver.sh");
  // (A shell that waits on a FIFO: a sleep would end at once, in virtual time.)
  std::ofstream(script) << "\"$1\" careless || exit $?\n"
                           "if grep -q fault \"$L6470EMU_SCENARIO\"; then\n"
                           "  mkfifo \"$2/held.$$\"\n"
                           "  setsid sh -c 'echo $$ > \"$1\"; read x < \"$2\"' sh \"$2/left.$$\" \"$2/held.$$\" &\n"
                           "  mkfifo \"$2/fifo.$$\"; read x < \"$2/fifo.$$\"\nfi\n";
  const RunResult r = run_program({l6470emu_program(), "campaign", "--chain", "chips=L6470 check=warn", "--faults", "ocd", "--at",
                                   "during_motion", "--wall-timeout", "4", "--json", path("c.json"), "--", "/bin/sh",
                                   script, client("campaign_driver"), dir_.string()},
                                  {}, 120);
  EXPECT_EQ(r.status, 1) << r.err;  // the rerun: hang
  EXPECT_NE(r.err.find("that reruns ended at a limit left running"), std::string::npos) << r.err;
  int left = 0;
  for (const auto& e : fs::directory_iterator(dir_))
    if (e.path().filename().string().rfind("left.", 0) == 0) {
      ++left;
      const pid_t pid = std::stoi(read(e.path().string()));
      EXPECT_NE(kill(pid, 0), 0) << "the setsid shell " << pid << " still runs";
    }
  EXPECT_EQ(left, 1);
}

TEST_F(Campaign, StoppedBySigtermItWritesTheReportsMarkedIncomplete) {
  // The reruns block where virtual time cannot see (a FIFO nobody opens); the clean run does not.
  const std::string script = path("driver.sh");
  std::ofstream(script) << "\"$1\" careless || exit $?\n"
                           "if grep -q fault \"$L6470EMU_SCENARIO\"; then mkfifo \"$2/fifo.$$\"; read x < \"$2/fifo.$$\"; fi\n";
  Background b({l6470emu_program(), "campaign", "--chain", "chips=L6470", "--faults", "ocd", "-j", "1", "--json",
                path("c.json"), "--junit", path("c.xml"), "--", "/bin/sh", script, client("campaign_driver"),
                dir_.string()});
  auto blocked = [&] {
    for (const auto& e : fs::directory_iterator(dir_))
      if (e.path().filename().string().rfind("fifo.", 0) == 0) return true;
    return false;
  };
  for (int i = 0; i < 1500 && !blocked(); ++i) usleep(20'000);
  ASSERT_TRUE(blocked()) << "the first rerun never reached its FIFO";
  const RunResult r = b.stop(SIGTERM, 30);
  EXPECT_EQ(r.status, 128 + SIGTERM) << r.err;
  const Json j = Json::parse(read(path("c.json")));
  EXPECT_EQ(j["complete"], false);
  EXPECT_LT(j["reruns"].size(), j["total"].get<std::size_t>());
  EXPECT_NE(read(path("c.xml")).find("incomplete"), std::string::npos);
}

}  // namespace
}  // namespace l6470emu::test
