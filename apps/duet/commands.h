// Each subcommand registers its options on the CLI app and returns the function that runs it.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace duet::app {

// Exit codes shared by every subcommand.
constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;  // bad input file, failed write, ...
constexpr int kExitUsage = 2;    // bad command line
constexpr int kExitLost = 3;     // duet follow: over half the input's frames were lost

using Command = std::function<int()>;

Command register_inspect(CLI::App& app);
Command register_convert(CLI::App& app);
Command register_follow(CLI::App& app);
Command register_serve(CLI::App& app);
Command register_eval(CLI::App& app);
Command register_improvise(CLI::App& app);
Command register_contacts(CLI::App& app);
Command register_retarget(CLI::App& app);
Command register_vmc_send(CLI::App& app);

}  // namespace duet::app
