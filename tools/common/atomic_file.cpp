#include "tools/common/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "tools/common/error.h"

namespace igi {
namespace {

std::atomic<int> g_counter{0};

void FsyncPath(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

AtomicOutput::AtomicOutput(std::filesystem::path final_path) : final_path_(std::move(final_path)) {
  const auto parent = final_path_.parent_path();
  if (!parent.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
    if (ec) {
      throw Error(DescribeProblem(parent.string(), "", "",
                                  "cannot create folder: " + ec.message()));
    }
  }
  // Built with += (GCC 12 warns falsely about operator+ chains under -O2: -Wrestrict).
  std::string name(".");
  name += final_path_.stem().string();
  name += ".tmp";
  name += std::to_string(::getpid());
  name += '-';
  name += std::to_string(g_counter++);
  name += final_path_.extension().string();
  temp_path_ = parent / name;
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(temp_path_, ec);
  }
}

void AtomicOutput::Commit() {
  if (committed_) return;
  FsyncPath(temp_path_);
  std::error_code ec;
  std::filesystem::rename(temp_path_, final_path_, ec);
  if (ec) {
    throw Error(DescribeProblem(final_path_.string(), "", "", "cannot write: " + ec.message()));
  }
  committed_ = true;
}

void WriteFileAtomic(const std::filesystem::path& path, std::string_view contents) {
  AtomicOutput out(path);
  {
    std::ofstream stream(out.temp_path(), std::ios::binary | std::ios::trunc);
    stream.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    stream.flush();
    if (!stream) {
      throw Error(DescribeProblem(path.string(), "", "", "cannot write: " + std::string(std::strerror(errno))));
    }
  }
  out.Commit();
}

void AppendLineDurable(const std::filesystem::path& path, std::string_view line) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw Error(DescribeProblem(path.string(), "", "", "cannot open for append: " + std::string(std::strerror(errno))));
  }
  std::string buffer(line);
  buffer.push_back('\n');
  size_t written = 0;
  while (written < buffer.size()) {
    const ssize_t n = ::write(fd, buffer.data() + written, buffer.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string reason = std::strerror(errno);
      ::close(fd);
      throw Error(DescribeProblem(path.string(), "", "", "cannot append: " + reason));
    }
    written += static_cast<size_t>(n);
  }
  ::fsync(fd);
  ::close(fd);
}

std::string ReadFileToString(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) {
    throw InputError(DescribeProblem(path.string(), "", "", "cannot read: " + std::string(std::strerror(errno))));
  }
  std::ostringstream buffer;
  buffer << stream.rdbuf();
  return buffer.str();
}

}  // namespace igi
