// duet: follow a dancer and answer with a virtual partner. See `duet --help`.
#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "command_line_hints.h"
#include "commands.h"

namespace {

// Runs a command so that no exception ends the tool with an abort (exit 134): the commands report
// bad input as errors, so anything that escapes is a bug, said as one, with exit 1.
int run_reporting_exceptions(const duet::app::Command& run) {
  try {
    // Lets the tests check this path (tests/apps/cli_first_hour_test.cc).
    if (std::getenv("DUET_TEST_THROW") != nullptr) throw std::runtime_error("DUET_TEST_THROW");
    return run();
  } catch (const std::bad_alloc&) {
    fmt::print(stderr,
               "duet: out of memory (the input or the options ask for more than this "
               "machine has)\n");
  } catch (const std::exception& e) {
    fmt::print(stderr, "duet: internal error: {} (please report it with the command line)\n",
               e.what());
  }
  return duet::app::kExitFailure;
}

}  // namespace

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
  add("vmc-send", "Play a take as VMC messages (OSC over UDP), for trying `serve --source vmc`",
      duet::app::register_vmc_send);

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
    if (sub->parsed()) return run_reporting_exceptions(run);
  }
  return duet::app::kExitUsage;
}
