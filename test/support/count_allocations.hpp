#pragma once
// Counts heap allocations made through operator new in one test binary (hot-path checks).
// Include it from exactly one file of a test executable: it replaces the global operator new.
// Every form of new and delete is replaced so that each pair stays malloc/free (a sanitizer
// build reports a mismatch when one form is left to the runtime).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"  // GCC cannot see the pairs match
#endif
#include <atomic>
#include <cstdlib>
#include <new>

static std::atomic<long> g_allocations{0};
namespace count_allocations_detail {
inline void* allocate(std::size_t n) noexcept {
  ++g_allocations;
  return std::malloc(n ? n : 1);
}
}  // namespace count_allocations_detail
void* operator new(std::size_t n) {
  if (void* p = count_allocations_detail::allocate(n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  if (void* p = count_allocations_detail::allocate(n)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  return count_allocations_detail::allocate(n);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  return count_allocations_detail::allocate(n);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
