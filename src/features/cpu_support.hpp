#pragma once
// Which vector extensions the running CPU has, for the features' runtime kernel dispatch (x86-64
// with GCC or clang only; callers guard with the same #if). Each kernel asks for exactly the
// extensions its target attribute names, so a kernel never runs on a CPU without them.
#if defined(__GNUC__) && defined(__x86_64__)
namespace spinradar::cpu {
inline bool hasAvx2() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
}
inline bool hasAvx2Fma() { return hasAvx2() && __builtin_cpu_supports("fma"); }
inline bool hasAvx512f() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f");
}
inline bool hasAvx512bw() { return hasAvx512f() && __builtin_cpu_supports("avx512bw"); }
/// What the matcher's kernel needs: AVX-512 with byte/word ops, vector popcount and 256-bit forms.
inline bool hasAvx512Popcnt() {
  return hasAvx512bw() && __builtin_cpu_supports("avx512vpopcntdq") &&
         __builtin_cpu_supports("avx512vl");
}
}  // namespace spinradar::cpu
#endif
