#include "tests/capture/fake_camera.h"

#include <fcntl.h>
#include <net/if.h>
#include <sched.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

namespace igi::capture::testing {
namespace {

bool WriteProcFile(const char* path, const std::string& text) {
  std::ofstream file(path);
  file << text;
  return bool(file.flush());
}

bool BringLoopbackUp() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return false;
  struct ifreq request {};
  std::strncpy(request.ifr_name, "lo", IFNAMSIZ - 1);
  bool ok = ::ioctl(fd, SIOCGIFFLAGS, &request) == 0;
  request.ifr_flags |= IFF_UP | IFF_RUNNING;
  ok = ok && ::ioctl(fd, SIOCSIFFLAGS, &request) == 0;
  ::close(fd);
  return ok;
}

bool Unshare() {
  if (::unshare(CLONE_NEWNET) == 0) return true;
  const uid_t uid = ::getuid();
  const gid_t gid = ::getgid();
  if (::unshare(CLONE_NEWUSER | CLONE_NEWNET) != 0) return false;
  WriteProcFile("/proc/self/setgroups", "deny");
  return WriteProcFile("/proc/self/uid_map", "0 " + std::to_string(uid) + " 1") &&
         WriteProcFile("/proc/self/gid_map", "0 " + std::to_string(gid) + " 1");
}

}  // namespace

bool EnterPrivateNetwork() {
  static const bool entered = Unshare() && BringLoopbackUp();
  return entered;
}

void IsolateFakeCameras() {
  if (EnterPrivateNetwork()) return;
  static const int fd = [] {
    const auto path = std::filesystem::temp_directory_path() / "igi_capture_fake_camera.lock";
    const int lock_fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (lock_fd >= 0) ::flock(lock_fd, LOCK_EX);
    return lock_fd;
  }();
  (void)fd;
}

bool GvcpPortInUse() {
  std::ifstream udp("/proc/self/net/udp");
  std::string line;
  while (std::getline(udp, line)) {
    // "  sl  local_address rem_address ..." with addresses as hex
    // "0100007F:0F74".
    if (line.find(":0F74 ") != std::string::npos &&
        (line.find("0100007F:0F74") != std::string::npos ||
         line.find("00000000:0F74") != std::string::npos)) {
      return true;
    }
  }
  return false;
}

ChildProcess::ChildProcess(const std::vector<std::string>& args,
                           const std::filesystem::path& log_path) {
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ != 0) return;  // parent (or fork failed: pid_ = -1)
  // Child: dies with the test process, however that ends (a crash, a killed test run), so no
  // fake camera outlives its test.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(127);
  const int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd >= 0) {
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::close(fd);
  }
  ::execvp(argv[0], argv.data());
  ::_exit(127);
}

ChildProcess::~ChildProcess() { Kill(); }

bool ChildProcess::Running() {
  if (pid_ <= 0) return false;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) {
    status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    pid_ = -1;
    return false;
  }
  return true;
}

int ChildProcess::Wait(double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (Running()) {
    if (std::chrono::steady_clock::now() > deadline) {
      Kill();
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return status_;
}

void ChildProcess::Kill() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGKILL);
  int status = 0;
  ::waitpid(pid_, &status, 0);
  status_ = 128 + SIGKILL;
  pid_ = -1;
}

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

int RunProcess(const std::vector<std::string>& args, double timeout_s, std::string* output) {
  const std::filesystem::path log = std::filesystem::temp_directory_path() /
                                    ("igi_capture_run_" + std::to_string(::getpid()) + ".log");
  std::filesystem::remove(log);
  ChildProcess process(args, log);
  const int code = process.Wait(timeout_s);
  if (output != nullptr) *output = ReadText(log);
  std::filesystem::remove(log);
  return code;
}

FakeCamera::FakeCamera(const std::string& serial, const std::filesystem::path& log_path,
                       const std::vector<std::string>& extra_args)
    : process_(
          [&] {
            std::vector<std::string> args = {"arv-fake-gv-camera-0.8", "-i", "127.0.0.1", "-s",
                                             serial};
            args.insert(args.end(), extra_args.begin(), extra_args.end());
            return args;
          }(),
          log_path) {
  // Returns as soon as the port is bound; the generous limit is for a loaded machine (a 5 s limit
  // failed once while a build ran beside the suite on 2 cores).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline && process_.Running()) {
    if (GvcpPortInUse()) {
      ready_ = true;
      // The control socket is bound; give the stream thread a moment to come up
      // too.
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace igi::capture::testing
