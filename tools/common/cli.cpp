#include "tools/common/cli.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>

#include "tools/common/error.h"
#include "tools/common/logging.h"
#include "tools/common/parallel.h"

#ifndef IGI_VERSION
#define IGI_VERSION "0.0.0"
#endif

namespace igi {

const char* Version() { return IGI_VERSION; }

void AddCommonFlags(CLI::App& app, CommonFlags* flags, bool computes) {
  app.set_version_flag("--version", std::string(app.get_name()) + " " + Version());
  app.add_flag("-v,--verbose", flags->verbose, "Log details to stderr");
  app.add_flag("-q,--quiet", flags->quiet, "Log only errors");
  if (computes) {
    app.add_option("--threads", flags->threads, "Worker threads (0 = all cores)")
        ->check(CLI::NonNegativeNumber);
  }
}

int RunMain(CLI::App& app, const CommonFlags& flags, int argc, char** argv,
            const std::function<int()>& body) {
  const std::string program = app.get_name();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::fprintf(stderr, "%s: error: %s (see --help)\n", program.c_str(), e.what());
    return static_cast<int>(ExitCode::kBadInput);
  }
  InitLogging(program, flags.quiet     ? LogLevel::kQuiet
                       : flags.verbose ? LogLevel::kDebug
                                       : LogLevel::kInfo);
  SetDefaultThreads(flags.threads);
  try {
    return body();
  } catch (const Error& e) {
    for (const std::string& line : e.Lines()) {
      std::fprintf(stderr, "%s: error: %s\n", program.c_str(), line.c_str());
    }
    return static_cast<int>(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: internal: %s\n", program.c_str(), e.what());
    return static_cast<int>(ExitCode::kFailed);
  }
}

void ParseArguments(CLI::App& app, const std::string& program, std::vector<std::string> args) {
  ProblemList problems;
  for (const std::string& arg : args) {
    const std::string name = arg.substr(0, arg.find('='));
    if (name.rfind("--", 0) != 0 || app.get_option_no_throw(name) == nullptr) {
      problems.Add("", name, arg.substr(std::min(arg.size(), name.size() + 1)),
                   "not an option of " + program);
    }
  }
  problems.ThrowIfAny();
  std::reverse(args.begin(), args.end());  // CLI11 takes a vector's arguments from its back
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    throw InputError(program + ": " + e.what());
  }
}

void RejectOutputInSceneFolder(const std::string& out_dir, const std::string& scene_path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path scene_dir = fs::absolute(fs::path(scene_path)).parent_path();
  if (fs::exists(out_dir) && fs::equivalent(fs::path(out_dir), scene_dir, ec)) {
    throw InputError(DescribeProblem("", "--out", out_dir,
                                     "must differ from the scene's folder (inputs are never "
                                     "modified)"));
  }
}

}  // namespace igi
