#pragma once
// Scaffolding shared by every igi executable (tools/igi-*.cpp): the common flags
// (--version, --threads, --verbose, --quiet), and the mapping of errors to one line per problem
// on stderr and the contract's exit codes (0 ok, 1 failed, 2 bad usage or input, 3 partial).

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace igi {

// The toolkit's version string ("0.1.0").
const char* Version();

struct CommonFlags {
  int threads = 0;  // 0 = all cores
  bool verbose = false;
  bool quiet = false;
};

// Adds --version, --verbose, --quiet and (when `computes`) --threads to `app`.
void AddCommonFlags(CLI::App& app, CommonFlags* flags, bool computes = true);

// Parses the command line, sets up logging and the thread default, then runs `body`, mapping
// what it throws to stderr lines ("igi-xxx: error: ...") and an exit code. Usage errors exit 2;
// --help and --version exit 0.
int RunMain(CLI::App& app, const CommonFlags& flags, int argc, char** argv,
            const std::function<int()>& body);

// Parses `args` ("--name=value" or "--name", in order) with `app`, as a command line without the
// program name: the flags of an executable given from elsewhere (the Python package's keyword
// arguments). Throws InputError naming `program` and the argument: an unknown option, a value
// the option refuses, a missing required one.
void ParseArguments(CLI::App& app, const std::string& program, std::vector<std::string> args);

// Throws InputError ("--out: DIR: must differ from the scene's folder") when `out_dir` is the
// folder of `scene_path`: a tool never writes into its input scene's folder.
void RejectOutputInSceneFolder(const std::string& out_dir, const std::string& scene_path);

}  // namespace igi
