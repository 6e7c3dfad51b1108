// What the CPU running the program has, for the kernels written for one instruction set.
#pragma once

#if defined(__x86_64__)
#include <cpuid.h>
#endif

namespace stokesrods {

/// Whether the CPU has AVX2, FMA and F16C (the AVX2 kernels' set; F16C read from cpuid, since
/// clang 14's __builtin_cpu_supports does not know its name). False off x86-64.
inline bool CpuHasAvx2FmaF16c() {
#if defined(__x86_64__)
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  if (__get_cpuid(1, &eax, &ebx, &ecx, &edx) == 0) return false;
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && (ecx & bit_F16C) != 0;
#else
  return false;
#endif
}

}  // namespace stokesrods
