// run_recordings / find_run_recordings: trace_path_for_chain forwards, and backwards through a
// folder listing with each candidate's header read to confirm its chain.
#include "tools/run_recordings.hpp"

#include <algorithm>
#include <filesystem>
#include <tuple>

#include "board/board_chain.hpp"
#include "board/trace_recorder.hpp"
#include "tools/trace_input.hpp"

namespace l6470emu {
namespace {

std::string node_name(const ChainConfig& chain) { return chain.path.substr(chain.path.rfind('/') + 1); }

}  // namespace

std::vector<ChainRecording> run_recordings(const BoardConfig& board, const std::string& path) {
  std::vector<ChainRecording> out;
  for (const ChainConfig& c : board.chains)
    out.push_back({node_name(c), trace_path_for_chain(path, node_name(c), board.chains.size())});
  return out;
}

std::vector<ChainRecording> find_run_recordings(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (path.empty() || fs::exists(path, ec)) return {};
  // The name of chain "\x01" splits into what comes before every chain's name and after it.
  const std::string marked = trace_path_for_chain(path, "\x01", 2);
  const std::size_t at = marked.find('\x01');
  const std::string before = marked.substr(0, at), after = marked.substr(at + 1);
  const std::size_t slash = before.rfind('/');
  const fs::path folder =
      slash == std::string::npos ? fs::path(".") : fs::path(slash == 0 ? "/" : before.substr(0, slash));
  const std::string prefix = slash == std::string::npos ? before : before.substr(slash + 1);
  struct Found {
    unsigned bus, cs;
    ChainRecording recording;
  };
  std::vector<Found> found;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() + after.size() || name.compare(0, prefix.size(), prefix) != 0 ||
        name.compare(name.size() - after.size(), after.size(), after) != 0)
      continue;
    const std::string chain = name.substr(prefix.size(), name.size() - prefix.size() - after.size());
    const std::string file = slash == std::string::npos ? name : before.substr(0, slash + 1) + name;
    try {
      TraceInputOptions options;
      options.format = TraceFormat::native;
      const TraceFile trace(file, options);
      const ChainDescription d = parse_chain_description(trace.header().board, file);
      if (!d.board || node_name(d.chain()) != chain) continue;
      found.push_back({d.chain().bus, d.chain().cs, {chain, file}});
    } catch (const std::exception&) {
      continue;  // not a recording of a chain: not one of the run's
    }
  }
  std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) {
    return std::tie(a.bus, a.cs, a.recording.chain) < std::tie(b.bus, b.cs, b.recording.chain);
  });
  std::vector<ChainRecording> out;
  for (Found& f : found) out.push_back(std::move(f.recording));
  return out;
}

}  // namespace l6470emu
