// Catches the command-line mistakes CLI11 reports misleadingly, before it parses: a misspelt
// subcommand ("A subcommand is required") and an unknown option, whose value CLI11 takes for a
// positional argument ("files: File does not exist: 60" for `duet inspect --fsp 60 a.bvh`).
// Both get a message naming the mistake and the closest valid name.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

namespace duet::app {

// The first mistake in `args` (argv without the program name) for `app` and its subcommands,
// as a message ("duet: unknown command 'folow' (did you mean 'follow'?)"), or nothing.
std::optional<std::string> find_command_line_mistake(const CLI::App& app,
                                                     const std::vector<std::string>& args);

// The candidate closest to `word` when it is close enough to be a likely misspelling (edits,
// including swapped neighbours, at most a third of the word's length, and at least 1).
std::optional<std::string> closest_name(const std::string& word,
                                        const std::vector<std::string>& candidates);

}  // namespace duet::app
