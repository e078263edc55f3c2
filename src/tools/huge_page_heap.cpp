#include "huge_page_heap.hpp"

#include <cstdint>
#include <cstdlib>

#if defined(__GLIBC__)
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace spinradar::cli {

bool preferHugePageHeap(size_t bytes) {
#if defined(__GLIBC__) && defined(MADV_HUGEPAGE)
  constexpr size_t kHuge = size_t(2) << 20;
  mallopt(M_ARENA_MAX, 1);                    // loader threads allocate from the main heap too
  mallopt(M_MMAP_THRESHOLD, 32 << 20);        // big blocks from the heap, not one mmap each
  mallopt(M_TRIM_THRESHOLD, 1 << 30);         // and the heap is not given back between scans
  mallopt(M_TOP_PAD, static_cast<int>(bytes));  // grow it once, by `bytes`
  // Grow the heap now, then mark its new top as huge-page memory (not touched: no memory used
  // until a buffer lands there).
  const uintptr_t before = reinterpret_cast<uintptr_t>(sbrk(0));
  void* probe = std::malloc(kHuge);
  const uintptr_t after = reinterpret_cast<uintptr_t>(sbrk(0));
  std::free(probe);
  const uintptr_t lo = (before + kHuge - 1) / kHuge * kHuge, hi = after / kHuge * kHuge;
  if (probe == nullptr || hi <= lo) return false;
  return madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE) == 0;
#else
  (void)bytes;
  return false;
#endif
}

}  // namespace spinradar::cli
