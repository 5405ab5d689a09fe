// One line and exit status 2 for every usage error of the l6470emu program, with the near miss
// named (core/near_miss.hpp, the helper the board description's errors use too).
#include "tools/cli_errors.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <ostream>

#include "core/near_miss.hpp"

namespace l6470emu {
namespace {

std::string quoted_list(const std::vector<std::string>& names, const char* last_joint) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? last_joint : ", ") + ("'" + names[i] + "'");
  return out;
}

std::string plain_list(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

/// Text from the command line in a message: control characters escaped, cut short.
std::string shown(const std::string& s) {
  std::string out;
  for (unsigned char c : s.substr(0, 60)) {
    if (c < 0x20 || c == 0x7f) {
      static const char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  return s.size() > 60 ? out + "..." : out;
}

std::vector<std::string> subcommand_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* s : app.get_subcommands([](const CLI::App*) { return true; })) names.push_back(s->get_name());
  return names;
}

/// Every spelling of every option of `app`: "--chain", "-o", "--output".
std::vector<std::string> option_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* o : app.get_options()) {
    for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
    for (const std::string& s : o->get_snames()) names.push_back("-" + s);
  }
  return names;
}

std::string without_dashes(const std::string& s) { return s.substr(std::min(s.find_first_not_of('-'), s.size())); }

/// "; did you mean '--chain'?" for an option: names compared without their dashes, so that
/// "-o" is not taken for "-h".
std::string option_suggestion(const std::string& word, const std::vector<std::string>& options) {
  std::vector<std::string> bare;
  for (const std::string& o : options) bare.push_back(without_dashes(o));
  std::vector<std::string> hits;
  for (const std::string& b : closest_matches(without_dashes(word), bare))
    for (const std::string& o : options)
      if (without_dashes(o) == b && std::find(hits.begin(), hits.end(), o) == hits.end()) hits.push_back(o);
  return hits.empty() ? "" : "; did you mean " + quoted_list(hits, " or ") + "?";
}

/// " ('-o' is an option of convert and plot)" when other subcommands take `option`.
std::string option_elsewhere(const CLI::App& app, const CLI::App* here, const std::string& option) {
  std::vector<std::string> owners;
  for (const CLI::App* s : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (s == here) continue;
    const std::vector<std::string> names = option_names(*s);
    if (std::find(names.begin(), names.end(), option) != names.end()) owners.push_back(s->get_name());
  }
  if (owners.empty()) return "";
  std::string list;
  for (std::size_t i = 0; i < owners.size(); ++i)
    list += (i == 0 ? "" : i + 1 == owners.size() ? " and " : ", ") + owners[i];
  return " ('" + option + "' is an option of " + list + ")";
}

int usage_error(const CLI::App& app, const CLI::ParseError& e, std::ostream& err) {
  // The deepest subcommand parsed ("coverage report", "campaign merge") names the mistake.
  const CLI::App* sub = nullptr;
  std::string path;
  for (const CLI::App* at = &app;;) {
    const std::vector<CLI::App*> parsed = at->get_subcommands();
    if (parsed.empty()) break;
    sub = at = parsed.back();
    path += " " + sub->get_name();
  }
  const CLI::App& where = sub != nullptr ? *sub : app;
  const std::string who = "l6470emu" + path;
  const std::string help = " (" + who + " --help)";
  std::string message = e.what();
  std::replace(message.begin(), message.end(), '\n', ' ');
  std::string line;
  if (dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr) {
    // "The following argument(s) was/were not expected: B A": CLI11 lists them last first, so
    // the last one is the first mistake.
    const auto colon = message.rfind(": ");
    std::string extra = colon == std::string::npos ? message : message.substr(colon + 2);
    extra = extra.substr(extra.rfind(' ') + 1);
    if (extra.size() > 1 && extra[0] == '-') {
      const std::string name = extra.substr(0, extra.find('='));
      const std::string near = option_suggestion(name, option_names(where));
      line = "unknown option '" + shown(name) + "'" + near;
      if (near.empty()) line += option_elsewhere(app, sub, name) + help;
    } else if (sub == nullptr) {
      const std::string near = did_you_mean(extra, subcommand_names(app));
      line = "unknown subcommand '" + shown(extra) + "'" + near + (near.empty() ? help : "");
    } else {
      line = "unexpected argument '" + shown(extra) + "'" + help;
    }
  } else if (dynamic_cast<const CLI::RequiredError*>(&e) != nullptr && sub == nullptr &&
             message.find("ubcommand") != std::string::npos) {
    line = "a subcommand is required: " + plain_list(subcommand_names(app)) + " (l6470emu --help)";
  } else {
    line = shown(message) == message ? message : message.substr(0, 320);
    if (line.find("did you mean") == std::string::npos) line += help;
  }
  err << who << ": " << line << "\n";
  return kUsageError;
}

}  // namespace

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  const std::vector<std::string> hits = closest_matches(word, candidates);
  return hits.empty() ? "" : "; did you mean " + quoted_list(hits, " or ") + "?";
}

CLI::Validator one_of(std::vector<std::string> names) {
  const std::string list = plain_list(names);
  return CLI::Validator(
      [names = std::move(names), list](std::string& value) -> std::string {
        if (std::find(names.begin(), names.end(), value) != names.end()) return {};
        return "'" + shown(value) + "' is not one of " + list + did_you_mean(value, names);
      },
      "one of " + list);
}

std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv, std::ostream& out, std::ostream& err) {
  // A first word that is no subcommand is a misspelt one (CLI11 would only say that one is required).
  if (argc >= 2 && argv[1][0] != '-' && argv[1][0] != '\0') {
    const std::vector<std::string> subs = subcommand_names(app);
    if (std::find(subs.begin(), subs.end(), argv[1]) == subs.end()) {
      const std::string near = did_you_mean(argv[1], subs);
      err << "l6470emu: unknown subcommand '" << shown(argv[1]) << "'" << near;
      if (near.empty()) err << " (" << plain_list(subs) << "; l6470emu --help)";
      err << "\n";
      return kUsageError;
    }
  }
  if (argc >= 2 && argv[1][0] == '-') {  // an option before any subcommand: only --help and --version
    const std::string word = std::string(argv[1]).substr(0, std::string(argv[1]).find('='));
    const std::vector<std::string> top = option_names(app);
    if (std::find(top.begin(), top.end(), word) == top.end()) {
      std::string near = option_suggestion(word, top);
      if (near.empty()) near = did_you_mean(without_dashes(word), subcommand_names(app));
      err << "l6470emu: unknown option '" << shown(word) << "'" << near;
      if (near.empty()) err << " (l6470emu --help)";
      err << "\n";
      return kUsageError;
    }
  }
  // A subcommand that passes its arguments on (ctl, and run's program after --) still has its
  // own options checked: those before its first word (CLI11 would name a word of the program).
  if (argc >= 2) {
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
      if (sub->get_name() != argv[1] || !(sub->get_prefix_command() || sub->get_name() == "run" || sub->get_name() == "campaign")) continue;
      for (int i = 2; i < argc && argv[i][0] == '-'; ++i) {
        const std::string arg = argv[i];
        if (arg == "--") break;
        // "-j4": a short option with its value attached.
        const bool short_attached = arg.size() > 2 && arg[1] != '-';
        const std::string word = short_attached ? arg.substr(0, 2) : arg.substr(0, arg.find('='));
        const CLI::Option* known = nullptr;
        for (const CLI::Option* o : sub->get_options()) {
          for (const std::string& l : o->get_lnames()) known = known != nullptr ? known : ("--" + l == word ? o : nullptr);
          for (const std::string& n : o->get_snames()) known = known != nullptr ? known : ("-" + n == word ? o : nullptr);
        }
        if (known == nullptr) {
          const std::string near = option_suggestion(word, option_names(*sub));
          err << "l6470emu " << sub->get_name() << ": unknown option '" << shown(word) << "'" << near;
          if (near.empty()) err << " (l6470emu " << sub->get_name() << " --help)";
          err << "\n";
          return kUsageError;
        }
        if (known->get_items_expected_min() > 0 && word == arg && !short_attached) ++i;  // its value follows
      }
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e, out, err);
  } catch (const CLI::RuntimeError& e) {  // a subcommand's own exit status
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    return usage_error(app, e, err);
  }
  return std::nullopt;
}

}  // namespace l6470emu
