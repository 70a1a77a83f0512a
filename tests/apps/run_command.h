// Runs the duet binary in a shell and captures its exit code and combined output.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace duet::testing {

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

inline CommandResult run_duet(const std::string& arguments) {
  const std::string command = std::string(DUET_BINARY) + " " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

inline std::string data_path(const std::string& relative) {
  return std::string(DUET_DATA_DIR) + "/" + relative;
}

// The salsa library file with the data folder, as `duet follow` / `duet eval` arguments.
inline const std::string kSalsaLibrary =
    std::string(DUET_TESTDATA_DIR) + "/../../libraries/cmu-salsa.toml --data-dir " + DUET_DATA_DIR;

}  // namespace duet::testing
