#pragma once
// Lets a whole-process run (odometry over a folder) take its big buffers on 2 MB pages.
#include <cstddef>

namespace spinradar::cli {

/// Makes glibc malloc serve every thread and every block up to 32 MB from the main heap,
/// reserves `bytes` at its top and marks that range MADV_HUGEPAGE. Why: on this project's
/// (virtual) machines a 4 KB page fault costs ~12 us of CPU, and a run's scans, images, PNG
/// buffers and per-thread buffers (each a fresh mmap by default, per thread arena) were ~5000
/// faults (~25 % of a 40-scan two-thread run's CPU); on the heap they are a few huge-page
/// faults. A hint only: without transparent huge pages nothing changes but where blocks live.
/// Call before the big allocations and before other threads start. Returns whether the range
/// could be marked.
bool preferHugePageHeap(size_t bytes = size_t(96) << 20);

}  // namespace spinradar::cli
