#pragma once
// Runs another executable as a child process (no shell), its stdout and stderr appended to a log
// file. Used by igi-run to chain the toolkit's executables.

#include <filesystem>
#include <string>
#include <vector>

namespace igi::pipeline {

struct ProcessResult {
  int exit_code = -1;      // the child's exit status; -1 when it was killed by a signal
  std::string last_error;  // the last line of the log that contains "error" (may be empty)
};

// Runs `executable` with `args`, appending both output streams to `log_file` (created, with its
// folder). Throws igi::Error when the process cannot be started.
ProcessResult RunProcess(const std::filesystem::path& executable,
                         const std::vector<std::string>& args,
                         const std::filesystem::path& log_file);

// The folder holding the running executable (/proc/self/exe), where igi-run finds its peers.
std::filesystem::path ExecutableDir();

// "a 'b c' d": a command line for logs (quoted where needed; not for a shell).
std::string CommandLine(const std::filesystem::path& executable,
                        const std::vector<std::string>& args);

}  // namespace igi::pipeline
