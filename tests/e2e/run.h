#pragma once
// Runs an igi executable from build/bin and captures its exit code, stdout and stderr.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace igi::test {

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// `args` is a shell-quoted argument string (use Quote for paths).
inline RunResult RunTool(const std::string& tool, const std::string& args) {
  static int counter = 0;
  const auto tmp = std::filesystem::temp_directory_path() /
                   ("igi_run_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  const std::string cmd = Quote(std::string(IGI_BIN_DIR) + "/" + tool) + " " + args + " >" +
                          Quote(tmp.string() + ".out") + " 2>" + Quote(tmp.string() + ".err");
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  auto slurp = [](const std::string& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    std::filesystem::remove(p);
    return ss.str();
  };
  r.out = slurp(tmp.string() + ".out");
  r.err = slurp(tmp.string() + ".err");
  return r;
}

}  // namespace igi::test
