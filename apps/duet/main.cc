// duet: follow a dancer and answer with a virtual partner. See `duet --help`.
#include <fmt/format.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "command_line_hints.h"
#include "commands.h"

int main(int argc, char** argv) {
  CLI::App app{
      "duet: performance-driven dance motion control of a virtual partner (Mousas 2018).\n"
      "Motion data: CMU Graphics Lab Motion Capture Database (mocap.cs.cmu.edu)."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "duet 0.1.0");

  std::map<CLI::App*, duet::app::Command> commands;
  auto add = [&](const char* name, const char* description, auto register_fn) {
    CLI::App* sub = app.add_subcommand(name, description);
    commands[sub] = register_fn(*sub);
  };
  add("inspect", "Describe a motion file: joints, frames, rate, channels, convention, extent",
      duet::app::register_inspect);
  add("convert", "Convert ASF+AMC or BVH to BVH (rescaled, resampled)", duet::app::register_convert);
  add("follow", "Follow a dancer through a library of duets and answer with the partner",
      duet::app::register_follow);
  add("serve", "Follow a live dancer (file replay, mocap stream, WebSocket) and serve the viewer",
      duet::app::register_serve);
  add("eval", "Measure followers on synthetic performances with ground truth from the takes",
      duet::app::register_eval);
  add("improvise", "Write a synthetic performance of a take (BVH) and its ground truth (CSV)",
      duet::app::register_improvise);
  add("contacts", "Print the hand-contact intervals of a captured duet, per hand pair",
      duet::app::register_contacts);
  add("retarget", "Put a motion onto another skeleton, keeping the body's directions and feet",
      duet::app::register_retarget);

  // Mistakes CLI11 would report misleadingly: a misspelt command, an unknown option.
  if (const std::optional<std::string> mistake = duet::app::find_command_line_mistake(
          app, std::vector<std::string>(argv + 1, argv + argc))) {
    fmt::print(stderr, "{}\n", *mistake);
    return duet::app::kExitUsage;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return duet::app::kExitUsage;
  }
  for (auto& [sub, run] : commands) {
    if (sub->parsed()) return run();
  }
  return duet::app::kExitUsage;
}
