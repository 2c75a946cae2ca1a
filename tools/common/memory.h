#pragma once
// The machine's memory and the process's use of it, for stages that budget their memory
// (STYLE.md §8): they estimate their peak before allocating and fit it to a budget.

#include <cstdint>

namespace igi {

inline constexpr double kGiB = 1024.0 * 1024.0 * 1024.0;

// The memory this process may use, in bytes: the machine's physical memory, or the control
// group's limit where one is set lower (a container, a Slurm job).
uint64_t AvailableMemoryBytes();

// The default memory budget, in bytes: AvailableMemoryBytes() less a margin for the system and
// other jobs (an eighth of it, at least 1 GiB), at least 1 GiB.
uint64_t DefaultMemoryBudgetBytes();

// The peak resident set size of this process so far, in bytes (getrusage's ru_maxrss).
uint64_t PeakResidentBytes();

}  // namespace igi
