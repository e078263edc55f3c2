#pragma once
// std::vector allocator for large per-geometry tables: blocks of 512 KB or more are 2 MB-aligned
// and marked MADV_HUGEPAGE, so that first touching them costs a few huge-page faults instead of
// hundreds of 4 KB ones. Why: on this project's (virtual) machines a 4 KB fault costs ~15 us of
// CPU; the Cartesian projector's ~12 MB of tables were ~40 ms of every process's start.
#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace spinradar {

template <class T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr size_t kMinBytes = size_t(512) << 10;  ///< smaller blocks: operator new
  static constexpr size_t kHugePage = size_t(2) << 20;

  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(size_t n) {
    const size_t bytes = n * sizeof(T);
    if (bytes < kMinBytes) return static_cast<T*>(::operator new(bytes));
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    ::madvise(p, rounded, MADV_HUGEPAGE);  // a hint: without it the pages are 4 KB, still correct
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t n) noexcept {
    if (n * sizeof(T) < kMinBytes)
      ::operator delete(p);
    else
      std::free(p);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
  template <class U>
  bool operator!=(const HugePageAllocator<U>&) const noexcept { return false; }
};

template <class T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace spinradar
