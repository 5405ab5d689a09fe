// The run's verdict from the program's end (tools/run_judgement.hpp).
#include "tools/run_judgement.hpp"

#include <sys/wait.h>

#include <algorithm>
#include <cstring>

#include "board/scenario.hpp"

namespace l6470emu {

RunOutcome RunJudgement::outcome() const {
  RunOutcome o;
  o.status = status;
  o.exited = exited;
  o.code = code;
  o.signal = signal;
  o.end_tick = end_tick;
  o.ended = ended;
  o.failures = failures;
  o.detail = detail;
  o.pin_reads = pin_reads;
  return o;
}

RunJudgement judge_run(const ProgramExit& run, std::optional<Tick> timeout) {
  RunJudgement j;
  std::optional<RunEnd> cause;
  const RunReport* cause_block = nullptr;
  for (const RunReport& b : run.blocks)
    if (b.end != RunEnd::exit && !cause) {
      cause = b.end;
      cause_block = &b;
    }
  if (run.wall_timeout || run.wall_guard) cause = RunEnd::timeout;
  if (!run.deadlock.empty()) cause = RunEnd::deadlock;
  // The processes that used the chips with a scenario bound are judged; else the program's own.
  std::vector<const RunReport*> judged;
  for (const RunReport& b : run.blocks)
    if (b.devices && b.scenario) judged.push_back(&b);
  if (judged.empty())
    for (const RunReport& b : run.blocks)
      if (b.pid == run.pid) judged.push_back(&b);
  for (const RunReport* b : judged) {
    j.expectations += b->outcome.judged;
    j.failures.insert(j.failures.end(), b->outcome.failures.begin(), b->outcome.failures.end());
    j.passed.insert(j.passed.end(), b->outcome.passed.begin(), b->outcome.passed.end());
    j.world.insert(j.world.end(), b->outcome.log.begin(), b->outcome.log.end());
    j.end_tick = std::max(j.end_tick, b->tick);
    for (const auto& p : b->outcome.pin_reads) {
      auto same = [&](const ScenarioOutcome::PinRead& q) { return q.chain == p.chain && q.chip == p.chip && q.pin == p.pin; };
      const auto it = std::find_if(j.pin_reads.begin(), j.pin_reads.end(), same);
      if (it == j.pin_reads.end()) j.pin_reads.push_back(p);
      else it->tick = std::max(it->tick, p.tick);
    }
  }
  if (cause_block) {
    j.end_tick = std::max(j.end_tick, cause_block->tick);
    j.detail = cause_block->detail;
  }
  if (run.wall_guard && !run.blocked.empty()) {
    j.detail = {"what each thread was blocked in when the guard ended it (the kernel's view, from /proc, where a "
                "process said nothing of its own waits):"};
    for (const std::string& line : run.blocked) j.detail.push_back("  " + line);
  }
  if (!run.deadlock.empty()) {
    j.detail = {"every process of the program waits on another of them, and none can end another's wait "
                "(each said what it waits on; run ended them all):"};
    for (const std::string& line : run.deadlock) j.detail.push_back("  " + line);
  }
  if (run.wall_timeout && timeout) j.end_tick = std::max(j.end_tick, *timeout);  // killed: no report of its own
  j.exited = WIFEXITED(run.wstatus);
  j.code = j.exited ? WEXITSTATUS(run.wstatus) : -1;
  j.signal = WIFSIGNALED(run.wstatus) ? WTERMSIG(run.wstatus) : 0;
  if (run.wall_guard)
    j.ended = "was stopped by the wall-clock guard after " + seconds_text(run.wall_guard_limit) +
              " of the host's time (--wall-timeout): it waited where virtual time cannot see (a raw system call, "
              "sigwait(), a FIFO or socket another process holds) or ran longer than that";
  else if (cause == RunEnd::timeout)
    j.ended = "stopped at the simulated time limit " + seconds_text(timeout.value_or(j.end_tick));
  else if (!run.deadlock.empty())
    j.ended = "deadlocked in virtual time, its processes waiting on each other";
  else if (cause == RunEnd::deadlock)
    j.ended = "deadlocked in virtual time";
  else if (cause == RunEnd::sanitizer)
    j.ended = "stopped by the driver sanitizer";
  else if (run.stopped_by)
    j.ended = std::string("was stopped: l6470emu run got signal ") + std::to_string(run.stopped_by) + " (" +
              strsignal(run.stopped_by) + ") and passed it on";
  else if (j.exited)
    j.ended = "exited with status " + std::to_string(j.code);
  else
    j.ended = std::string("was killed by signal ") + std::to_string(j.signal) + " (" + strsignal(j.signal) + ")";

  if (cause == RunEnd::timeout) j.status = kRunTimedOut;
  else if (cause == RunEnd::deadlock) j.status = kRunDeadlocked;
  else if (cause == RunEnd::sanitizer) j.status = kRunSanitizerError;
  else if (!j.exited || j.code != 0) j.status = kRunProgramFailed;
  else if (!j.failures.empty()) j.status = kRunExpectationFailed;
  else if (judged.empty()) {  // with or without a scenario: nothing says how the run went
    j.status = kRunNotStarted;
    j.why = " (it left no report: it ended by _exit() or a signal before exit(), or the preload was not loaded)";
  }
  // Stopped by a signal to run: whatever the program did, the run did not finish (128 + N).
  if (run.stopped_by) {
    j.status = 128 + run.stopped_by;
    j.why.clear();
  }
  // Without a report (killed by a signal, _exit()) nothing says when it ended: no "at 0 s".
  j.when_known = !judged.empty() || cause_block || run.wall_timeout;
  return j;
}

}  // namespace l6470emu
