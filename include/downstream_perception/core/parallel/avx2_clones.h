// DP_AVX2_CLONES: put before a function whose loops vectorise twice as wide with AVX2. On x86-64
// Linux, GCC then builds an AVX2 copy next to the baseline x86-64 one and the loader picks the copy
// the CPU runs (an ifunc), so the package still runs on any x86-64. No FMA in the AVX2 copy: both
// give bit-identical results. Elsewhere (other compilers, CPUs, systems) it expands to nothing.
// Only on functions with external linkage: the loader picks a file-local function's copy while
// it relocates the library, before a sanitizer's runtime is up (ThreadSanitizer crashed there).
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define DP_AVX2_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define DP_AVX2_CLONES
#endif
