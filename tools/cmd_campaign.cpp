// `l6470emu campaign`: the clean run and every rerun are `l6470emu run` processes of this same
// program (each in a process group of its own, so that a stuck one is ended whole); their
// recordings give the injection points, whether the driver read the fault's flag and whether
// its traffic changed. Where the program is single-threaded at a rerun's injection tick, the rerun
// is a fork of one more clean run taken there (a snapshot: linux/fork_plan.hpp, the preload's
// fork_server.cpp), judged as `run` would judge it (tools/run_judgement.hpp); the others start
// from the beginning.
#include "tools/cmd_campaign.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>
#include <tuple>

#include "board/coverage_file.hpp"
#include "board/board.hpp"
#include "board/scenario_runner.hpp"
#include "board/trace_recorder.hpp"
#include "core/near_miss.hpp"
#include "linux/board_config_file.hpp"
#include "linux/clock.hpp"
#include "linux/fork_plan.hpp"
#include "board/run_report.hpp"
#include "linux/scenario_file.hpp"
#include "linux/scenario_yaml.hpp"
#include "spi/trace.hpp"
#include "tools/campaign_plan.hpp"
#include "tools/cli_errors.hpp"
#include "tools/left_processes.hpp"
#include "tools/output_check.hpp"
#include "tools/campaign_report.hpp"
#include "tools/cmd_report.hpp"
#include "tools/run_judgement.hpp"
#include "tools/run_outcome.hpp"
#include "tools/trace_input.hpp"

extern char** environ;

namespace l6470emu {
namespace {

namespace fs = std::filesystem;

std::atomic<int> g_stop{0};  // the signal that asked the campaign to stop (0: none)
extern "C" void on_campaign_stop_signal(int sig) { g_stop.store(sig); }

std::string self_exe() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string("l6470emu");
}

// A word as a POSIX shell reads it back.
std::string shell_word(const std::string& w) {
  if (!w.empty() && w.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-./=:,+@%") ==
                        std::string::npos)
    return w;
  std::string out = "'";
  for (const char c : w) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// A name made of the letters a file name can safely carry.
std::string file_word(const std::string& s) {
  std::string out;
  for (const char c : s) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ? c : '_';
  return out;
}

// A program run to its end in a process group of its own, its output to `out_path` (empty:
// inherited); killed whole after `wall_limit_s` or when the campaign is stopped.
struct Ended {
  int wstatus = 0;
  bool wall_killed = false;  // written under g_watch.m until the process was waited for
  bool stopped = false;
  bool started = false;
};
struct Watched {
  pid_t pid;
  std::chrono::steady_clock::time_point deadline;
  Ended* end;
};
struct {
  std::mutex m;
  std::condition_variable cv;
  std::vector<Watched> running;
} g_watch;
Ended run_process(const std::vector<std::string>& argv, const std::string& out_path, double wall_limit_s) {
  Ended end;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (!out_path.empty()) {
    posix_spawn_file_actions_addopen(&actions, 1, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  }
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setpgroup(&attr, 0);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK);
  std::vector<std::string> args = argv;
  std::vector<char*> cargv;
  for (auto& a : args) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  pid_t pid = 0;
  const int error = posix_spawn(&pid, cargv[0], &actions, &attr, cargv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (error != 0) return end;
  end.started = true;
  {
    std::lock_guard lock(g_watch.m);
    g_watch.running.push_back(Watched{pid, std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(wall_limit_s)), &end});
  }
  while (waitpid(pid, &end.wstatus, 0) < 0 && errno == EINTR) {
  }
  {
    std::lock_guard lock(g_watch.m);
    std::erase_if(g_watch.running, [pid](const Watched& w) { return w.pid == pid; });
  }
  kill(-pid, SIGKILL);  // whatever the program left behind in its group
  return end;
}

// The guard of every run in progress: ends the whole process group of one past its wall-clock
// limit, or of all of them once the campaign is asked to stop. Lives while the campaign runs.
class Watchdog {
 public:
  Watchdog() : thread_([this] { loop(); }) {}
  ~Watchdog() {
    {
      std::lock_guard lock(g_watch.m);
      done_ = true;
    }
    g_watch.cv.notify_all();
    thread_.join();
  }

 private:
  void loop() {
    std::unique_lock lock(g_watch.m);
    while (!done_) {
      const auto now = std::chrono::steady_clock::now();
      const bool stop = g_stop.load() != 0;
      for (Watched& w : g_watch.running) {
        if (w.end->wall_killed || w.end->stopped) continue;
        if (stop || now >= w.deadline) {
          (stop ? w.end->stopped : w.end->wall_killed) = true;
          kill(-w.pid, SIGKILL);
        }
      }
      g_watch.cv.wait_for(lock, std::chrono::milliseconds(20));
    }
  }
  bool done_ = false;
  std::thread thread_;
};

// Each frame's CS-fall tick and a hash of its MOSI bytes, in order.
std::vector<std::pair<Tick, std::uint64_t>> frame_hashes(const std::string& path) {
  std::vector<std::pair<Tick, std::uint64_t>> out;
  TraceFile file(path, TraceInputOptions{});
  auto reader = file.read();
  TraceEvent e;
  while (reader->next(e)) {
    if (e.kind != TraceEventKind::frame) continue;
    std::uint64_t h = 1469598103934665603ull;
    for (const std::uint8_t b : e.mosi) h = (h ^ b) * 1099511628211ull;
    out.emplace_back(e.tick, h ^ e.mosi.size());
  }
  return out;
}

bool traffic_differs_after(const std::vector<std::pair<Tick, std::uint64_t>>& clean,
                           const std::vector<std::pair<Tick, std::uint64_t>>& rerun, Tick tick) {
  auto from = [tick](const auto& v) {
    return std::lower_bound(v.begin(), v.end(), std::make_pair(tick, std::uint64_t{0}));
  };
  auto a = from(clean), b = from(rerun);
  if (clean.end() - a != rerun.end() - b) return true;
  for (; a != clean.end(); ++a, ++b)
    if (a->second != b->second) return true;
  return false;
}

struct PlannedRerun {
  std::size_t index = 0;
  const FaultSpec* fault = nullptr;
  std::size_t chip_slot = 0;  // into the campaign's chip list
  InjectionPoint point;
};

}  // namespace

CampaignCommand::CampaignCommand(CLI::App& app) {
  cmd_ = app.add_subcommand("campaign", "rerun a program with every fault the chips can raise, at every point of its run, and judge each rerun");
  cmd_->footer(
      "Exit status: 0 no rerun failed (by default: none silent_failure, hang, deadlock or crash), 1 some did, 2 usage, "
      "board, scenario or output error (nothing ran), 3-7 the clean run's own status when it did not pass, 128+N "
      "stopped by signal N (the reports of the reruns that ran are written, marked incomplete). docs/campaigns.md");
  auto* board = cmd_->add_option("--board", board_file_, "board description file (as for run)");
  auto* chain = cmd_->add_option("--chain", chain_, "board description text or a bare chain (as for run)");
  board->excludes(chain);
  cmd_->add_option("--scenario", scenario_file_, "scenario file: its actions run in every rerun and its expectations are the oracle");
  cmd_->add_option("--faults", faults_, "faults to raise, comma separated, or all (default): every fault each chip allows");
  cmd_->add_option("--points", points_, "injection points: phases (default) or every-command");
  cmd_->add_option("--chips", only_chips_, "only these chips, comma separated, as numbered (1, 0,2, spidev0.1:0)");
  cmd_->add_option("--at", only_points_, "only the injection points of these names, comma separated (during_motion,at_Move_2)");
  cmd_->add_option("-j,--jobs", jobs_, "reruns at once (default: the number of CPUs)");
  cmd_->add_option("--coverage", coverage_,
                   "merge the clean run's interface coverage into this file (docs/coverage.md); reruns collect none");
  cmd_->add_option("--shard", shard_, "run only shard K of N (K/N): reruns K-1, K-1+N, ...; join with campaign merge");
  cmd_->add_option("--json", json_, "write the report as JSON (reproducing scenarios are written beside it)");
  cmd_->add_option("--junit", junit_, "write a JUnit XML report: one testcase per fault and chip");
  cmd_->add_option("--html", html_,
                   "write the report page (docs/report.md): the clean run's traces (every chain it used) with the "
                   "matrix");
  cmd_->add_option("--fail-on", fail_on_,
                   "verdicts that fail the campaign (default silent_failure,hang,deadlock,crash; also detected, survived, "
                   "survived-unread)");
  cmd_->add_option("--timeout", timeout_, "simulated time limit of each run (default: the scenario's, else twice the clean run and at least 10 s more)");
  cmd_->add_option("--wall-timeout", wall_timeout_s_, "wall-clock seconds a rerun may take before it is judged hang (default 60)");
  cmd_->add_option("--reproducers", reproducers_,
                   "which reruns get a reproducing scenario file: failing (default: silent_failure, hang, deadlock, crash "
                   "and what --fail-on fails) or all")
      ->check(one_of({"failing", "all"}));
  cmd_->add_option("--snapshots", snapshots_,
                   "yes (default): a rerun forks from one more clean run at its injection tick where the program is "
                   "single-threaded there (docs/campaigns.md, Snapshots); no: every rerun starts from the beginning")
      ->check(one_of({"yes", "no"}));
  cmd_->add_flag("--list", list_, "run the clean run and print the faults and injection points it gives, without rerunning");
  cmd_->add_option("program", program_, "the program and its arguments (after --)");
  merge_ = cmd_->add_subcommand("merge", "join the JSON reports of a campaign's shards into the report of the whole");
  merge_->add_option("reports", merge_inputs_, "the shards' JSON reports")->required();
  merge_->add_option("-o,--output", merge_output_, "the joined report")->required();
}

std::optional<int> CampaignCommand::run() {
  if (!*cmd_) return std::nullopt;
  if (*merge_) return run_merge();
  return run_campaign();
}

int CampaignCommand::run_merge() {
  auto fail = [](const std::string& line) {
    std::cerr << "l6470emu campaign merge: " << line << "\n";
    return kRunUsage;
  };
  if (const std::string why = output_problem(merge_output_, merge_inputs_); !why.empty())
    return fail("cannot write " + merge_output_ + ": " + why);
  std::vector<CampaignReport> parts;
  for (const std::string& path : merge_inputs_) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return fail(path + ": cannot be read");
    std::string text((std::istreambuf_iterator<char>(in)), {});
    std::string error;
    auto r = parse_campaign_json(text, error);
    if (!r) return fail(path + ": " + error);
    parts.push_back(std::move(*r));
  }
  std::string error;
  const auto merged = merge_campaign_reports(parts, error);
  if (!merged) return fail(error);
  if (!write_whole_file(merge_output_, campaign_json(*merged))) return fail("cannot write " + merge_output_);
  std::cerr << "l6470emu campaign merge: " << campaign_summary(*merged) << " -> " << merge_output_ << "\n";
  FailOn on;
  for (const RerunResult& r : merged->reruns)
    if (r.fails(on)) return 1;
  return 0;
}

int CampaignCommand::run_campaign() {
  auto usage = [](const std::string& line) {
    std::cerr << "l6470emu campaign: " << line << "\n";
    return kRunUsage;
  };
  // 1. Everything the campaign is told, checked before anything runs.
  if (board_file_.empty() && chain_.empty()) return usage("give the board: --board FILE or --chain DESC");
  if (program_.empty()) return usage("give the program to run after --");
  std::string chain_text = chain_;
  if (!chain_text.empty() && chain_text.find('=') == std::string::npos) chain_text = "chips=" + chain_text;
  ParseResult parsed = board_file_.empty() ? parse_board_config(chain_text, "--chain") : load_board_config_file(board_file_);
  if (!parsed.config) return usage(parsed.error.message);
  BoardConfig config = std::move(*parsed.config);
  if (config.chains.empty()) return usage("the board description has no chain (chips=...)");
  Scenario user;
  if (!scenario_file_.empty()) {
    ScenarioParse sp = load_scenario_file(scenario_file_);
    if (!sp.scenario) return usage(sp.error);
    user = std::move(*sp.scenario);
    // Every rerun's scenario is this one written back with the fault's steps added.
    if (const ScenarioParse back = parse_scenario_yaml(scenario_yaml(user), scenario_file_); !back.scenario)
      return usage("the scenario cannot be written into the reruns' scenarios (its text is not UTF-8?): " + back.error);
  }
  std::optional<Tick> user_timeout = user.timeout_ticks;
  if (!timeout_.empty()) {
    user_timeout = parse_scenario_duration(timeout_);
    if (!user_timeout || *user_timeout == 0)
      return usage("--timeout " + quoted_text(timeout_) + " is not a duration (30, 2.5s, 250ms, 1min)");
  }
  PointSelection selection = PointSelection::phases;
  if (points_ == "every-command") selection = PointSelection::every_command;
  else if (points_ != "phases") {
    const std::string near = closest_names(points_, {"phases", "every-command"});
    return usage("--points " + quoted_text(points_) + " is not phases or every-command" + (near.empty() ? "" : " (did you mean " + near + "?)"));
  }
  unsigned shard_k = 1, shard_n = 1;
  if (!shard_.empty()) {
    char slash = 0, extra = 0;
    if (std::sscanf(shard_.c_str(), "%u%c%u%c", &shard_k, &slash, &shard_n, &extra) != 3 || slash != '/' || shard_n == 0 ||
        shard_k == 0 || shard_k > shard_n)
      return usage("--shard " + quoted_text(shard_) + " is not K/N with 1 <= K <= N (1/3, 2/3, 3/3)");
  }
  FailOn fail_on;
  if (!fail_on_.empty()) {
    std::string error;
    auto on = parse_fail_on(fail_on_, error);
    if (!on) return usage(error);
    fail_on = *on;
  }
  if (!(wall_timeout_s_ > 0)) return usage("--wall-timeout takes a number of seconds above 0");
  const std::vector<std::string> inputs{board_file_, scenario_file_, program_.front()};
  for (const std::string* out : {&json_, &junit_})
    if (cmd_->count(*out == json_ ? "--json" : "--junit") > 0 || !out->empty())
      if (const std::string why = output_problem(*out, inputs); !why.empty())
        return usage("cannot write " + quoted_text(*out) + ": " + why);
  if (!json_.empty() && json_ == junit_) return usage("--json and --junit name the same file");
  if (!html_.empty()) {
    if (const std::string why = output_problem(html_, inputs); !why.empty()) return usage("cannot write " + quoted_text(html_) + ": " + why);
    if (html_ == json_ || html_ == junit_) return usage("--html names the same file as another output");
  }
  // Coverage: the clean run's only (L6470EMU_COVERAGE asks the same); the faulted reruns collect none.
  if (const char* env = std::getenv(kCoverageEnv); env && *env && cmd_->count("--coverage") == 0) coverage_ = env;
  unsetenv(kCoverageEnv);
  if (!coverage_.empty() || cmd_->count("--coverage") > 0) {
    if (const std::string why = check_coverage_output(coverage_); !why.empty()) return usage("--coverage: " + why);
    if (coverage_ == json_ || coverage_ == junit_) return usage("--coverage names the same file as another output");
    coverage_ = absolute_path(coverage_);
  }

  // The chips, and the faults asked for.
  Board probe(config, [](std::string_view) {}, real_host_clock());
  if (!scenario_file_.empty()) {
    try {
      ScenarioRunner check(probe, user);
    } catch (const std::invalid_argument& e) {
      return usage(std::string("scenario ") + e.what());
    }
  }
  std::vector<const FaultSpec*> asked;
  std::vector<std::string> fault_names;
  for (const FaultSpec& f : campaign_faults()) fault_names.emplace_back(f.name);
  if (faults_ == "all") {
    for (const FaultSpec& f : campaign_faults()) asked.push_back(&f);
  } else {
    for (const std::string& word : comma_list(faults_)) {
      const FaultSpec* f = find_campaign_fault(word);
      if (!f) {
        const std::string near = closest_names(word, fault_names);
        return usage("--faults: " + quoted_text(word) + " is not a fault" + (near.empty() ? "" : " (did you mean " + near + "?)") +
                     "; faults: " + [&] {
                       std::string l;
                       for (const auto& n : fault_names) l += (l.empty() ? "" : ", ") + n;
                       return l;
                     }());
      }
      if (std::find(asked.begin(), asked.end(), f) == asked.end()) asked.push_back(f);
    }
  }
  std::vector<const FaultSpec*> selected;
  for (const FaultSpec* f : asked) {
    std::string why;
    bool any = false;
    for (std::size_t c = 0; c < probe.chain_count(); ++c)
      for (std::size_t k = 0; k < probe.chip_count(c); ++k) {
        const Chip& chip = probe.chain(c).chip(k);
        const std::string no = fault_unavailable(f->fault, chip.variant(), chip.has_axis());
        any = any || no.empty();
        if (!no.empty() && why.empty()) why = no;
      }
    if (any) selected.push_back(f);
    else if (faults_ != "all") return usage("--faults: " + std::string(f->name) + " cannot be raised on this board: " + why);
  }
  if (selected.empty()) return usage("no fault to raise on this board");
  for (const std::string& w : only_chips_.empty() ? std::vector<std::string>{} : comma_list(only_chips_)) {
    bool found = false;
    for (std::size_t c = 0; c < probe.chain_count(); ++c)
      for (std::size_t k = 0; k < probe.chip_count(c); ++k)
        found = found || w == std::to_string(k) || w == probe.chain_name(c) + ":" + std::to_string(k);
    if (!found) return usage("--chips: the board has no chip " + quoted_text(w));
  }

  // 2. The clean run, recorded.
  const char* tmp = std::getenv("TMPDIR");
  std::string work = std::string(tmp && *tmp ? tmp : "/tmp") + "/l6470emu-campaign-XXXXXX";
  if (!mkdtemp(work.data())) return usage("cannot create a directory in " + fs::path(work).parent_path().string());
  work = fs::absolute(work.c_str()).string();  // (the snapshots' plan names absolute paths)
  struct RemoveWork {
    std::string dir;
    ~RemoveWork() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } remove_work{work};
  struct sigaction sa {};
  sa.sa_handler = on_campaign_stop_signal;
  sigemptyset(&sa.sa_mask);
  struct sigaction old_int {}, old_term {};
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);
  struct RestoreSignals {
    struct sigaction i, t;
    ~RestoreSignals() {
      sigaction(SIGINT, &i, nullptr);
      sigaction(SIGTERM, &t, nullptr);
    }
  } restore{old_int, old_term};

  const std::string exe = self_exe();
  std::vector<std::string> board_args;
  if (!board_file_.empty()) board_args = {"--board", board_file_};
  else board_args = {"--chain", chain_};
  std::vector<std::string> clean_argv{exe, "run"};
  clean_argv.insert(clean_argv.end(), board_args.begin(), board_args.end());
  if (!scenario_file_.empty()) clean_argv.insert(clean_argv.end(), {"--scenario", scenario_file_});
  if (user_timeout) clean_argv.insert(clean_argv.end(), {"--timeout", scenario_duration_text(*user_timeout)});
  if (!coverage_.empty()) clean_argv.insert(clean_argv.end(), {"--coverage", coverage_});
  const std::string clean_trace = work + "/clean.trace", clean_outcome = work + "/clean.json";
  clean_argv.insert(clean_argv.end(), {"--record", clean_trace, "--outcome", clean_outcome, "--"});
  clean_argv.insert(clean_argv.end(), program_.begin(), program_.end());
  Watchdog watchdog;
  // A run ended whole at the wall-clock limit or by a stop (SIGKILL to its group) cannot end what
  // its program left in sessions of their own (setsid): those come to the campaign, which ends
  // them once the reruns are over.
  adopt_orphans_from_now();
  std::cerr << "l6470emu campaign: the clean run\n";
  const Ended clean_end = run_process(clean_argv, "", wall_timeout_s_);
  if (g_stop.load()) return 128 + g_stop.load();
  const auto clean = read_run_outcome(clean_outcome);
  if (clean_end.wall_killed) {
    std::cerr << "l6470emu campaign: the clean run took longer than --wall-timeout " << wall_timeout_s_ << " s; no fault was injected\n";
    return kRunTimedOut;
  }
  if (!clean || clean->status != kRunPassed) {
    const int status = clean ? clean->status : kRunNotStarted;
    std::cerr << "l6470emu campaign: the clean run did not pass (run's exit " << status << "); no fault was injected\n";
    return status;
  }
  const auto trace_of = [&](const std::string& base, std::size_t c) {
    return config.chains.size() == 1 ? base : trace_path_for_chain(base, probe.chain_name(c), config.chains.size());
  };
  std::vector<ChipRun> chips;
  std::vector<std::vector<std::pair<Tick, std::uint64_t>>> clean_frames(config.chains.size());
  try {
    for (std::size_t c = 0; c < config.chains.size(); ++c) {
      if (!fs::exists(trace_of(clean_trace, c))) {  // the program never opened this chain: nothing to inject
        for (std::size_t k = 0; k < probe.chip_count(c); ++k) {
          ChipRun idle;
          idle.chain = c;
          idle.index = k;
          idle.number = probe.chip_numbering(c).number_of(k);
          idle.chain_name = probe.chain_name(c);
          idle.variant = &probe.chain(c).chip(k).variant();
          idle.has_axis = probe.chain(c).chip(k).has_axis();
          chips.push_back(idle);
        }
        continue;
      }
      std::vector<ChipRun> on_chain = read_clean_run(trace_of(clean_trace, c), c, config, clean->end_tick);
      std::vector<std::vector<Tick>> ticks(on_chain.size());
      for (std::size_t k = 0; k < on_chain.size(); ++k)
        for (const InjectionPoint& p : injection_points(on_chain[k], selection)) ticks[k].push_back(p.tick);
      sample_rotor_positions(trace_of(clean_trace, c), c, config, on_chain, ticks);
      // Chips in the order users number them.
      std::sort(on_chain.begin(), on_chain.end(), [](const ChipRun& a, const ChipRun& b) { return a.number < b.number; });
      chips.insert(chips.end(), on_chain.begin(), on_chain.end());
      clean_frames[c] = frame_hashes(trace_of(clean_trace, c));
    }
  } catch (const std::exception& e) {
    std::cerr << "l6470emu campaign: the clean run's recording cannot be read: " << e.what() << "\n";
    return kRunNotStarted;
  }

  // 3. The plan: fault by fault, chip by chip, point by point.
  std::vector<std::vector<InjectionPoint>> points(chips.size());
  for (std::size_t s = 0; s < chips.size(); ++s) points[s] = injection_points(chips[s], selection);
  std::vector<bool> chip_wanted(chips.size(), only_chips_.empty());
  for (const std::string& w : only_chips_.empty() ? std::vector<std::string>{} : comma_list(only_chips_)) {
    bool found = false;
    for (std::size_t s = 0; s < chips.size(); ++s)
      if (w == std::to_string(chips[s].number) || w == chips[s].chain_name + ":" + std::to_string(chips[s].number)) {
        chip_wanted[s] = true;
        found = true;
      }
    if (!found) return usage("--chips: the board has no chip " + quoted_text(w));
  }
  const std::vector<std::string> wanted_points = only_points_.empty() ? std::vector<std::string>{} : comma_list(only_points_);
  std::vector<PlannedRerun> plan;
  for (const FaultSpec* f : selected)
    for (std::size_t s = 0; s < chips.size(); ++s) {
      if (!chip_wanted[s] || !fault_unavailable(f->fault, *chips[s].variant, chips[s].has_axis).empty()) continue;
      for (const InjectionPoint& p : points[s])
        if (wanted_points.empty() || std::find(wanted_points.begin(), wanted_points.end(), p.name) != wanted_points.end())
          plan.push_back(PlannedRerun{plan.size(), f, s, p});
    }
  const bool user_oracle = has_expectations(user);
  const Tick rerun_timeout =
      user_timeout ? *user_timeout : std::max(2 * clean->end_tick, clean->end_tick + 10 * kTicksPerSecond);
  // A campaign with nothing to rerun must not read as a pass: the program never spoke to a chip.
  const bool nothing = plan.empty() && only_chips_.empty() && only_points_.empty();
  if (nothing)
    std::cerr << "l6470emu campaign: the clean run sent no command to any chip that could take a fault: nothing was "
                 "injected\n";
  if (list_) {
    std::cout << "clean run: " << clean->ended << " at " << seconds_text(clean->end_tick) << "\n";
    for (std::size_t s = 0; s < chips.size(); ++s) {
      const ChipRun& c = chips[s];
      std::cout << c.chain_name << " chip " << c.number << " (" << c.variant->name << "): " << c.commands.size()
                << " commands\n  faults:";
      for (const FaultSpec* f : selected)
        if (fault_unavailable(f->fault, *c.variant, c.has_axis).empty()) std::cout << " " << f->name;
      std::cout << "\n  points:\n";
      for (const InjectionPoint& p : points[s])
        std::cout << "    " << p.name << " at " << seconds_text(p.tick)
                  << (p.after_command.empty() ? "" : " after " + p.after_command) << "\n";
    }
    std::cout << plan.size() << " reruns (oracle: " << (user_oracle ? "the scenario's expectations" : "the clean run's end state")
              << ")\n";
    return 0;
  }

  // 4. The reruns.
  std::vector<std::size_t> mine;
  for (const PlannedRerun& p : plan)
    if (p.index % shard_n == shard_k - 1) mine.push_back(p.index);
  const std::string out_dir = !json_.empty() ? fs::path(json_).parent_path().string()
                              : !junit_.empty() ? fs::path(junit_).parent_path().string()
                                                : std::string();
  const std::string stem = !json_.empty() ? fs::path(json_).stem().string() : std::string("campaign");
  const std::vector<ScenarioStep> oracle = user_oracle ? std::vector<ScenarioStep>{} : clean_run_oracle(chips);
  const bool several_chains = config.chains.size() > 1;

  std::vector<std::optional<RerunResult>> results(mine.size());
  std::atomic<std::size_t> next{0}, done{0};
  const bool tty = isatty(2) != 0;
  std::mutex print;
  // Each rerun's directory, scenario and the steps a snapshot adds to the clean run's.
  struct Prepared {
    std::string name, yaml, dir, scenario_path, outcome_path, trace;
    Scenario scenario;
  };
  auto prepare = [&](std::size_t slot) {
    const PlannedRerun& p = plan[mine[slot]];
    const ChipRun& chip = chips[p.chip_slot];
    std::int64_t rotor = 0;
    for (const auto& [t, v] : chip.rotor_at)
      if (t == p.point.tick) rotor = v;
    const std::string name = file_word(stem + "." + std::string(p.fault->name) + "." +
                                       (several_chains ? chip.chain_name + "." : std::string()) + "chip" +
                                       std::to_string(chip.number) + "." + p.point.name) + ".yaml";
    Scenario s;
    s.name = (user.name.empty() ? std::string("campaign") : user.name) + ": " + std::string(p.fault->name) + " on " +
             chip.chain_name + " chip " + std::to_string(chip.number) + " at " + p.point.name;
    s.timeout_ticks = rerun_timeout;
    s.steps = user.steps;
    for (ScenarioStep& st : fault_steps(p.fault->fault, chip, p.point.tick, rotor)) {
      st.where = "the fault";
      s.steps.push_back(std::move(st));
    }
    s.steps.insert(s.steps.end(), oracle.begin(), oracle.end());
    const std::string yaml = scenario_yaml(
        s, "A rerun of l6470emu campaign: " + std::string(p.fault->name) + " (" + std::string(p.fault->what) + ")\non " +
               chip.chain_name + " chip " + std::to_string(chip.number) + " at " + seconds_text(p.point.tick) + " (" +
               p.point.name + (p.point.after_command.empty() ? "" : ", after " + p.point.after_command) + ")");
    const std::string dir = work + "/" + std::to_string(p.index);
    fs::create_directory(dir);
    Prepared out{name, yaml, dir, dir + "/" + name, dir + "/outcome.json", dir + "/run.trace", std::move(s)};
    // A snapshot's child adds what the user's scenario lacks: the fault and the oracle.
    Scenario added;
    added.steps.assign(out.scenario.steps.begin() + static_cast<std::ptrdiff_t>(user.steps.size()), out.scenario.steps.end());
    write_whole_file(dir + "/" + fork_files::steps, serialize_scenario(added));
    return out;
  };
  std::vector<Prepared> prepared(mine.size());
  for (std::size_t slot = 0; slot < mine.size(); ++slot) prepared[slot] = prepare(slot);

  // What a rerun came to, from its outcome and recording.
  auto judge = [&](std::size_t slot, const std::optional<RunOutcome>& outcome, const Ended& ended) {
    const PlannedRerun& p = plan[mine[slot]];
    const ChipRun& chip = chips[p.chip_slot];
    const Prepared& prep = prepared[slot];
    const std::string& name = prep.name;
    const std::string& yaml = prep.yaml;
    const Scenario& s = prep.scenario;
    const std::string& trace = prep.trace;
    RerunResult r;
    r.index = p.index;
    r.fault = p.fault->name;
    r.chain = chip.chain_name;
    r.chip = chip.number;
    r.point = p.point.name;
    r.tick = p.point.tick;
    r.after_command = p.point.after_command;
    r.verdict = classify_rerun(outcome, ended.wall_killed);
    r.exit = outcome ? outcome->status : ended.wall_killed ? kRunTimedOut : kRunNotStarted;
    r.program = ended.wall_killed ? "stopped at the campaign's wall-clock limit" : outcome ? outcome->ended : "left no outcome";
    if (outcome && !outcome->failures.empty()) {
      ScenarioFailure f = outcome->failures.front();
      // Steps of the generated file are named by what they came from: the user's file and line,
      // the fault, or the clean run's end.
      const auto reread = parse_scenario_yaml(yaml, name);
      if (reread.scenario)
        for (std::size_t i = 0; i < reread.scenario->steps.size() && i < s.steps.size(); ++i)
          if (reread.scenario->steps[i].where == fs::path(f.where).filename().string()) f.where = s.steps[i].where;
      r.first_failure = f;
    }
    const std::string flag = fault_flag(p.fault->fault, *chip.variant);
    try {
      const std::string rerun_trace = trace_of(trace, chip.chain);
      std::vector<ChipRun> seen = read_clean_run(rerun_trace, chip.chain, config, outcome ? outcome->end_tick : 0);
      if (!flag.empty()) {
        const RegisterInfo* status_reg = chip.variant->find(Reg::STATUS);
        bool read = false;
        for (const ChipRun& c : seen)
          if (c.number == chip.number)
            for (const DecodedCommand& d : c.commands)
              read = read || (d.end > p.point.tick &&
                              (d.command == Command::GetStatus ||
                               (d.command == Command::GetParam && status_reg && d.param == status_reg->address)));
        // ... or looked at its FLAG or BUSY pin at or after the fault's tick.
        if (outcome)
          for (const auto& pr : outcome->pin_reads)
            read = read || (pr.chain == chip.chain_name && pr.chip == chip.number && pr.tick >= p.point.tick);
        r.flag_read = read;
      }
      r.traffic_differs = traffic_differs_after(clean_frames[chip.chain], frame_hashes(rerun_trace), p.point.tick);
    } catch (const std::exception&) {
      if (!flag.empty()) r.flag_read = false;
      r.traffic_differs = true;
    }
    std::string repro_path = out_dir.empty() ? name : out_dir + "/" + name;
    r.command = "l6470emu run";
    for (const std::string& a : board_args) r.command += " " + shell_word(a);
    r.command += " --scenario " + shell_word(repro_path) + " --";
    for (const std::string& a : program_) r.command += " " + shell_word(a);
    if (reproducers_ == "all" || r.verdict == Verdict::silent_failure || r.verdict == Verdict::hang || r.verdict == Verdict::deadlock ||
        r.verdict == Verdict::crash || r.fails(fail_on)) {
      if (write_whole_file(repro_path, yaml)) r.reproducer = repro_path;
    }
    results[slot] = std::move(r);
  };
  // A rerun from the beginning: `run` of its scenario.
  auto one = [&](std::size_t slot) {
    const Prepared& prep = prepared[slot];
    write_whole_file(prep.scenario_path, prep.yaml);
    std::vector<std::string> argv{exe, "run"};
    argv.insert(argv.end(), board_args.begin(), board_args.end());
    argv.insert(argv.end(), {"--scenario", prep.scenario_path, "--record", prep.trace, "--outcome", prep.outcome_path, "--"});
    argv.insert(argv.end(), program_.begin(), program_.end());
    const Ended ended = run_process(argv, prep.dir + "/output.txt", wall_timeout_s_);
    if (ended.stopped) return;
    judge(slot, read_run_outcome(prep.outcome_path), ended);
    const std::size_t n = ++done;
    if (tty) {
      std::lock_guard lock(print);
      std::cerr << "\rl6470emu campaign: " << n << "/" << mine.size() << " reruns" << std::flush;
    }
  };
  unsigned jobs = jobs_ ? jobs_ : std::max(1u, std::thread::hardware_concurrency());
  jobs = std::min<unsigned>(jobs, static_cast<unsigned>(std::max<std::size_t>(1, mine.size())));
  std::cerr << "l6470emu campaign: " << plan.size() << " reruns"
            << (shard_n > 1 ? " (shard " + std::to_string(shard_k) + "/" + std::to_string(shard_n) + ": " + std::to_string(mine.size()) + ")" : "")
            << ", " << jobs << " at a time\n";
  // Snapshots: one more clean run, whose program forks each rerun at its injection tick (where it
  // can: single-threaded there). The others, and all of them with --snapshots no, start from the
  // beginning. Either way a rerun is judged the same (docs/campaigns.md, Snapshots).
  std::vector<std::size_t> todo;  // the reruns that start from the beginning
  std::vector<bool> forked(mine.size(), false);
  if (snapshots_ == "yes" && !mine.empty() && work.find('\n') == std::string::npos) {
    const std::string server = work + "/snapshots";
    fs::create_directory(server);
    ForkPlan fp;
    fp.children = jobs;
    fp.wall_ns = static_cast<std::int64_t>(wall_timeout_s_ * 1e9);
    const std::string server_trace = server + "/run.trace";
    for (std::size_t c = 0; c < config.chains.size(); ++c) fp.recordings.push_back(trace_of(server_trace, c));
    std::vector<std::size_t> by_tick(mine.size());
    for (std::size_t slot = 0; slot < mine.size(); ++slot) by_tick[slot] = slot;
    std::stable_sort(by_tick.begin(), by_tick.end(),
                     [&](std::size_t a, std::size_t b) { return plan[mine[a]].point.tick < plan[mine[b]].point.tick; });
    for (const std::size_t slot : by_tick) fp.jobs.push_back(ForkPlan::Job{plan[mine[slot]].point.tick, prepared[slot].dir});
    const std::string plan_path = server + "/plan";
    write_whole_file(plan_path, format_fork_plan(fp));
    std::vector<std::string> argv{exe, "run"};
    argv.insert(argv.end(), board_args.begin(), board_args.end());
    if (!scenario_file_.empty()) argv.insert(argv.end(), {"--scenario", scenario_file_});
    argv.insert(argv.end(), {"--timeout", scenario_duration_text(rerun_timeout), "--wall-timeout", "3000000000", "--record",
                             server_trace, "--outcome", server + "/outcome.json", "--"});
    argv.insert(argv.end(), program_.begin(), program_.end());
    setenv(kForkPlanEnv, plan_path.c_str(), 1);
    run_process(argv, server + "/output.txt", 1e8);  // each rerun has its limit; the clean run passed
    unsetenv(kForkPlanEnv);
    std::string first_reason;
    std::vector<std::tuple<std::size_t, std::optional<RunOutcome>, Ended>> ended_reruns;
    for (std::size_t slot = 0; slot < mine.size(); ++slot) {
      const std::string& dir = prepared[slot].dir;
      std::ifstream ended_file(dir + "/" + fork_files::ended);
      long long pid = 0;
      int wstatus = 0;
      if (!(ended_file >> pid >> wstatus)) {
        if (first_reason.empty()) {
          std::ifstream why(dir + "/" + fork_files::not_forked);
          std::getline(why, first_reason);
        }
        continue;
      }
      ProgramExit pe;
      pe.pid = static_cast<pid_t>(pid);
      pe.wstatus = wstatus;
      std::ifstream report_file(dir + "/" + fork_files::report, std::ios::binary);
      pe.blocks = parse_run_reports(std::string((std::istreambuf_iterator<char>(report_file)), {}));
      Ended ended;
      ended.started = true;
      ended.wstatus = wstatus;
      ended.wall_killed = fs::exists(dir + "/" + fork_files::wall_killed);
      // As a plain rerun stopped at the wall-clock limit: no outcome of its own.
      const std::optional<RunOutcome> outcome =
          ended.wall_killed ? std::nullopt : std::optional<RunOutcome>(judge_run(pe, rerun_timeout).outcome());
      ended_reruns.emplace_back(slot, outcome, ended);
      forked[slot] = true;
    }
    // Their recordings read in parallel, as the reruns from the beginning are.
    std::atomic<std::size_t> at{0};
    std::vector<std::thread> readers;
    for (unsigned w = 0; w < jobs; ++w)
      readers.emplace_back([&] {
        for (std::size_t i; (i = at++) < ended_reruns.size();) {
          const auto& [slot, outcome, ended] = ended_reruns[i];
          judge(slot, outcome, ended);
          ++done;
        }
      });
    for (auto& t : readers) t.join();
    const std::size_t from_snapshots = ended_reruns.size();
    if (from_snapshots < mine.size() && first_reason.empty())
      first_reason = "the program's first process took no snapshot: a firmware program, a shell around the driver that "
                     "ends by _exit(), or a program the preload does not reach";
    std::cerr << "l6470emu campaign: " << from_snapshots << " of " << mine.size() << " reruns forked from snapshots"
              << (from_snapshots < mine.size() && !first_reason.empty() ? " (not the others: " + first_reason + ")" : "")
              << "\n";
  }
  for (std::size_t slot = 0; slot < mine.size(); ++slot)
    if (!forked[slot] && !g_stop.load()) todo.push_back(slot);
  std::vector<std::thread> workers;
  for (unsigned w = 0; w < jobs; ++w)
    workers.emplace_back([&] {
      for (std::size_t i; !g_stop.load() && (i = next++) < todo.size();) one(todo[i]);
    });
  for (auto& t : workers) t.join();
  if (const LeftProcesses left = end_left_processes(std::chrono::milliseconds(0)); !left.running.empty()) {
    std::string names;
    for (const std::string& r : left.running) names += (names.empty() ? "" : ", ") + r;
    std::cerr << "l6470emu campaign: ended with " << (left.killed ? "SIGTERM, then SIGKILL, " : "SIGTERM ")
              << left.running.size() << " process" << (left.running.size() == 1 ? "" : "es")
              << " that reruns ended at a limit left running (" << names << ")\n";
  }
  if (tty) std::cerr << "\n";

  // 5. The report.
  CampaignReport report;
  report.program = program_;
  report.board = board_file_.empty() ? chain_ : board_file_;
  report.scenario = scenario_file_;
  report.oracle = user_oracle ? "scenario" : "clean_run";
  for (const FaultSpec* f : selected) report.faults.emplace_back(f->name);
  report.points = points_;
  report.clean_end_tick = clean->end_tick;
  report.rerun_timeout_ticks = rerun_timeout;
  report.total = plan.size();
  if (shard_n > 1) report.shard = std::make_pair(shard_k, shard_n);
  for (auto& r : results)
    if (r) report.reruns.push_back(std::move(*r));
  report.complete = report.reruns.size() == mine.size();
  std::cout << campaign_matrix(report, fail_on);
  std::cout << "l6470emu campaign: " << campaign_summary(report) << "\n";
  int status = nothing ? 1 : 0;
  for (const RerunResult& r : report.reruns)
    if (r.fails(fail_on)) status = 1;
  if (!json_.empty() && !write_whole_file(json_, campaign_json(report))) {
    std::cerr << "l6470emu campaign: cannot write " << json_ << "\n";
    status = kRunUsage;
  }
  if (!junit_.empty() && !write_whole_file(junit_, campaign_junit(report, fail_on))) {
    std::cerr << "l6470emu campaign: cannot write " << junit_ << "\n";
    status = kRunUsage;
  }
  if (!html_.empty()) {  // the clean run's page with the matrix
    ReportArgs page;
    for (std::size_t c = 0; c < config.chains.size(); ++c)
      if (fs::exists(trace_of(clean_trace, c))) {  // (a chain the program never opened has no recording)
        page.traces.push_back(trace_of(clean_trace, c));
        page.traces_shown.push_back(config.chains.size() == 1
                                        ? "(the clean run's recording)"
                                        : "(the clean run's recording of " + probe.chain_name(c) + ")");
      }
    if (!coverage_.empty()) page.coverage = {coverage_};
    page.campaign_report = report;
    page.output = html_;
    page.title = "campaign: " + program_.front();
    if (page.traces.empty())
      std::cerr << "l6470emu campaign --html: no page: the clean run never used a chain (nothing was recorded)\n";
    else if (run_report(page, std::cerr, "campaign --html") != 0)
      status = kRunUsage;
  }
  if (g_stop.load()) {
    std::cerr << "l6470emu campaign: stopped by signal " << g_stop.load() << " after " << report.reruns.size() << " of "
              << mine.size() << " reruns; the reports say incomplete\n";
    return 128 + g_stop.load();
  }
  return status;
}

}  // namespace l6470emu
