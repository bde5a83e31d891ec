#pragma once
// Private to libcore: the attribute that compiles a kernel three times (AVX-512, AVX2+FMA,
// baseline x86-64) and picks the clone for the running CPU at load time (GCC target_clones),
// so the binaries stay portable while the hot loops vectorise.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define IMPINGE_SIMD_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define IMPINGE_SIMD_CLONES
#endif
