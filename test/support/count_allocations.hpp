#pragma once
// Counts heap allocations made through operator new in one test binary (hot-path checks).
// Include it from exactly one file of a test executable: it replaces the global operator new.
// (The counting operator new pairs malloc with free on purpose.)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#include <atomic>
#include <cstdlib>
#include <new>

static std::atomic<long> g_allocations{0};
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
