#include "command_line_hints.h"

#include <algorithm>
#include <cctype>
#include <limits>

namespace duet::app {

namespace {

// Optimal string alignment distance: insertions, deletions, substitutions and swaps of two
// neighbours ("fsp" -> "fps" is one edit).
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

// "--name" for every long option of `app`, including those in its option groups.
void collect_long_options(const CLI::App& app, std::vector<std::string>& out) {
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& name : option->get_lnames()) out.push_back("--" + name);
  }
  for (const CLI::App* group :
       app.get_subcommands([](const CLI::App* a) { return a->get_name().empty(); })) {
    collect_long_options(*group, out);
  }
}

std::vector<std::string> subcommand_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub :
       app.get_subcommands([](const CLI::App* a) { return !a->get_name().empty(); })) {
    names.push_back(sub->get_name());
  }
  return names;
}

const CLI::App* find_subcommand(const CLI::App& app, const std::string& name) {
  for (const CLI::App* sub :
       app.get_subcommands([&](const CLI::App* a) { return a->get_name() == name; })) {
    return sub;
  }
  return nullptr;
}

std::string did_you_mean(const std::optional<std::string>& name, const char* quote) {
  return name ? std::string(" (did you mean ") + quote + *name + quote + "?)" : "";
}

}  // namespace

std::optional<std::string> closest_name(const std::string& word,
                                        const std::vector<std::string>& candidates) {
  const std::size_t allowed = std::max<std::size_t>(1, word.size() / 3);
  std::optional<std::string> best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (const std::string& candidate : candidates) {
    const std::size_t d = edit_distance(word, candidate);
    if (d <= allowed && d < best_distance) {
      best = candidate;
      best_distance = d;
    }
  }
  return best;
}

std::optional<std::string> find_command_line_mistake(const CLI::App& app,
                                                     const std::vector<std::string>& args) {
  const CLI::App* current = &app;
  std::string prefix = "duet";
  for (const std::string& arg : args) {
    if (arg == "--") break;  // what follows are values, whatever they look like
    const bool long_option = arg.size() > 2 && arg.starts_with("--");
    const bool short_option =
        arg.size() == 2 && arg[0] == '-' && std::isalpha(static_cast<unsigned char>(arg[1])) != 0;
    if (long_option || short_option) {
      const std::string name = arg.substr(0, arg.find('='));
      // Options of the main app (--help, --version) are understood after a subcommand too.
      if (current->get_option_no_throw(name) || app.get_option_no_throw(name)) continue;
      std::vector<std::string> names;
      collect_long_options(*current, names);
      return prefix + ": unknown option " + name + did_you_mean(closest_name(name, names), "") +
             "; `" + prefix + " --help` lists the options";
    }
    if (current == &app && !arg.starts_with('-')) {
      const CLI::App* sub = find_subcommand(app, arg);
      if (sub == nullptr) {
        const std::vector<std::string> names = subcommand_names(app);
        std::string list;
        for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
        return "duet: unknown command '" + arg + "'" + did_you_mean(closest_name(arg, names), "'") +
               "; the commands are " + list;
      }
      current = sub;
      prefix = "duet " + arg;
    }
  }
  return std::nullopt;
}

}  // namespace duet::app
