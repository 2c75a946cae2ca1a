#pragma once
// Test helpers: Aravis's fake GigE Vision camera (arv-fake-gv-camera-0.8) as a
// child process on 127.0.0.1, a private network namespace per test process, and
// bounded child processes.

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace igi::capture::testing {

// Moves this process (and its future children) into a new network namespace
// with its own loopback, once per process. False when the system forbids it
// (the tests then share the host's 127.0.0.1). Call before starting any thread.
bool EnterPrivateNetwork();

// Isolates this test process from other fake-camera tests: a private network
// namespace, or else an exclusive lock (held until the process exits) on a file
// in the temp folder.
void IsolateFakeCameras();

// True when something already listens on 127.0.0.1:3956 (the GVCP port) in this
// namespace.
bool GvcpPortInUse();

// A child process; killed (SIGKILL) and reaped in the destructor if still
// running.
class ChildProcess {
 public:
  // Starts `args` (args[0] looked up in PATH) with stdout and stderr appended
  // to `log_path`.
  ChildProcess(const std::vector<std::string>& args, const std::filesystem::path& log_path);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  bool Running();
  // Waits at most `timeout_s`; returns the exit code, 128 + signal, or -1 on
  // timeout (the process is then killed).
  int Wait(double timeout_s);
  void Kill();

 private:
  pid_t pid_ = -1;
  int status_ = -1;
};

// Runs to completion (bounded); returns the exit code (-1 on timeout) and fills
// `output`.
int RunProcess(const std::vector<std::string>& args, double timeout_s, std::string* output);

// The fake camera with serial `serial` on 127.0.0.1; the constructor waits
// (bounded) until it listens. Extra args, e.g. {"-r", "1000"} for lost packets.
class FakeCamera {
 public:
  FakeCamera(const std::string& serial, const std::filesystem::path& log_path,
             const std::vector<std::string>& extra_args = {});
  bool ready() const { return ready_; }
  void Kill() { process_.Kill(); }

 private:
  ChildProcess process_;
  bool ready_ = false;
};

std::string ReadText(const std::filesystem::path& path);

}  // namespace igi::capture::testing
