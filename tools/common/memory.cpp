#include "tools/common/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <string>

namespace igi {
namespace {

// The cgroup (v2, then v1) memory limit in bytes; 0 when none is set or readable.
uint64_t CgroupLimitBytes() {
  for (const char* path :
       {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(path);
    std::string value;
    if (!(in >> value) || value == "max") continue;
    try {
      const unsigned long long v = std::stoull(value);
      if (v > 0 && v < (1ULL << 60)) return v;
    } catch (...) {
    }
  }
  return 0;
}

}  // namespace

uint64_t AvailableMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  uint64_t bytes = pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : uint64_t(8 * kGiB);
  const uint64_t limit = CgroupLimitBytes();
  if (limit > 0) bytes = std::min(bytes, limit);
  return bytes;
}

uint64_t DefaultMemoryBudgetBytes() {
  const uint64_t total = AvailableMemoryBytes();
  const uint64_t margin = std::max<uint64_t>(uint64_t(kGiB), total / 8);
  return std::max<uint64_t>(uint64_t(kGiB), total > margin ? total - margin : 0);
}

uint64_t PeakResidentBytes() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return uint64_t(usage.ru_maxrss) * 1024;  // Linux reports kilobytes
}

}  // namespace igi
