// Child processes for the linux tests.
#include "run_program.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>
#include <chrono>

extern char** environ;

namespace l6470emu::test {
namespace {

std::string temp_dir() {
  const char* t = std::getenv("TMPDIR");
  return t && *t ? t : "/tmp";
}

std::string unique_path(const std::string& what) {
  static int counter = 0;
  return temp_dir() + "/l6470emu-test-" + std::to_string(getpid()) + "-" + std::to_string(++counter) + "-" + what;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

pid_t spawn(const std::vector<std::string>& argv, const Env& env, const std::string& out, const std::string& err) {
  std::vector<std::string> envs;
  for (char** e = environ; *e; ++e) {
    const std::string kv = *e;
    if (kv.rfind("LD_PRELOAD=", 0) == 0 || kv.rfind("L6470EMU_", 0) == 0) continue;
    envs.push_back(kv);
  }
  for (const auto& [k, v] : env) envs.push_back(k + "=" + v);
  std::vector<char*> cargv, cenv;
  for (const auto& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
  cargv.push_back(nullptr);
  for (const auto& e : envs) cenv.push_back(const_cast<char*>(e.c_str()));
  cenv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);
    const int o = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int n = ::open("/dev/null", O_RDONLY);
    dup2(n, 0);
    dup2(o, 1);
    dup2(e, 2);
    execve(cargv[0], cargv.data(), cenv.data());
    _exit(127);
  }
  return pid;
}

int wait_for(pid_t pid, double timeout_s) {
  timespec start{};
  clock_gettime(CLOCK_MONOTONIC, &start);
  for (;;) {
    int st = 0;
    const pid_t r = waitpid(pid, &st, WNOHANG);
    if (r == pid) return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    if ((now.tv_sec - start.tv_sec) + (now.tv_nsec - start.tv_nsec) / 1e9 > timeout_s) {
      kill(-pid, SIGKILL);
      kill(pid, SIGKILL);
      waitpid(pid, &st, 0);
      return 128 + SIGKILL;
    }
    usleep(2000);
  }
}

}  // namespace

RunResult run_program(const std::vector<std::string>& argv, const Env& env, double timeout_s) {
  const std::string out = unique_path("out"), err = unique_path("err");
  const pid_t pid = spawn(argv, env, out, err);
  RunResult r;
  r.status = wait_for(pid, timeout_s);
  r.out = slurp(out);
  r.err = slurp(err);
  unlink(out.c_str());
  unlink(err.c_str());
  return r;
}

Background::Background(const std::vector<std::string>& argv, const Env& env)
    : out_path_(unique_path("bg-out")), err_path_(unique_path("bg-err")) {
  pid_ = spawn(argv, env, out_path_, err_path_);
}

Background::~Background() {
  if (!done_) stop(SIGKILL, 5);
  unlink(out_path_.c_str());
  unlink(err_path_.c_str());
}

RunResult Background::stop(int sig, double timeout_s) {
  if (!done_) {
    kill(pid_, sig);
    return wait(timeout_s);
  }
  return result_;
}

RunResult Background::wait(double timeout_s) {
  if (!done_) {
    result_.status = wait_for(pid_, timeout_s);
    result_.out = slurp(out_path_);
    result_.err = slurp(err_path_);
    done_ = true;
  }
  return result_;
}

std::string Background::out() const { return slurp(out_path_); }

ServeDaemon::ServeDaemon(const std::string& chain, const std::vector<std::string>& extra)
    : socket_(unique_path("serve.sock")) {
  std::vector<std::string> argv = {l6470emu_program(), "serve", "--chain", chain, "--socket", socket_};
  argv.insert(argv.end(), extra.begin(), extra.end());
  process_ = std::make_unique<Background>(argv);
  for (int i = 0; i < 1000 && !ready_; ++i) {
    ready_ = process_->out().find("listening on") != std::string::npos;
    if (!ready_) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

Env ServeDaemon::env() const { return {{"LD_PRELOAD", preload_library()}, {"L6470EMU_SOCKET", socket_}}; }

RunResult ServeDaemon::ctl(const std::vector<std::string>& words) const {
  std::vector<std::string> argv = {l6470emu_program(), "ctl", "--socket", socket_};
  argv.insert(argv.end(), words.begin(), words.end());
  return run_program(argv);
}

std::map<std::string, std::string> key_values(const std::string& out) {
  std::map<std::string, std::string> m;
  std::istringstream in(out);
  for (std::string w; in >> w;)
    if (const auto eq = w.find('='); eq != std::string::npos) m[w.substr(0, eq)] = w.substr(eq + 1);
  return m;
}

std::string build_dir() { return L6470EMU_BINARY_DIR; }
std::string preload_library() { return build_dir() + "/libl6470emu-preload.so"; }
std::string l6470emu_program() { return build_dir() + "/l6470emu"; }
std::string client(const std::string& name) { return build_dir() + "/tests/linux/clients/" + name; }
std::string script(const std::string& name) { return std::string(L6470EMU_SOURCE_DIR) + "/tests/linux/scripts/" + name; }
std::string system_python() { return "/usr/bin/python3"; }

std::string missing_prerequisites() {
  auto exists = [](const std::string& p) { return access(p.c_str(), F_OK) == 0; };
  if (!exists(preload_library())) return "the preload library was not built: " + preload_library();
  if (!exists(system_python())) return "Debian's /usr/bin/python3 is missing (scripts/setup.sh installs it)";
  const RunResult r = run_program({system_python(), "-c", "import spidev, gpiod"});
  if (r.status != 0) return "python3-spidev / python3-libgpiod are not installed (scripts/setup.sh installs them)";
  for (const char* t : {"/usr/bin/gpiodetect", "/usr/bin/gpioinfo", "/usr/bin/gpioget", "/usr/bin/gpiomon"})
    if (!exists(t)) return std::string("Debian's gpiod tools are missing: ") + t + " (scripts/setup.sh installs them)";
  return "";
}

std::string temp_socket_path(const std::string& tag) { return unique_path(tag + ".sock"); }

}  // namespace l6470emu::test
