#pragma once
// Private to libcore: the attribute that compiles a kernel three times (AVX-512, AVX2+FMA,
// baseline x86-64) and picks the clone for the running CPU at load time (GCC target_clones),
// so the binaries stay portable while the hot loops vectorise.
// -DIMPINGE_SIMD_NO_AVX512 leaves the AVX-512 clones and wide kernels (IMPINGE_SIMD_CLONES, detail::use_wide_vectors)
// out, so that a machine with AVX-512 runs what a CPU without it gets (most desktop CPUs): to measure that path,
// as tools/ab-cli compares two builds.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#ifdef IMPINGE_SIMD_NO_AVX512
#define IMPINGE_SIMD_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define IMPINGE_SIMD_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#endif
/// The AVX2 and baseline clones only, for a kernel whose AVX-512 form is written apart (IMPINGE_SIMD_WIDE):
/// kernels over GCC vectors of 64 bytes (16 floats, 8 doubles), which fill one AVX-512 register but two AVX2
/// ones, where GCC spilled every row to the stack (the distance scans' lower bounds and the joint centre's
/// normal sums: 1.6x and 1.3x the CPU time of lhdl-ct's motion and `impinge rom` without AVX-512).
#define IMPINGE_SIMD_CLONES_NARROW __attribute__((target_clones("arch=x86-64-v3", "default")))
/// The AVX-512 form of such a kernel (x86-64-v4), called only where detail::use_wide_vectors() holds.
#define IMPINGE_SIMD_WIDE __attribute__((target("arch=x86-64-v4")))
#else
#define IMPINGE_SIMD_CLONES
#define IMPINGE_SIMD_CLONES_NARROW
#define IMPINGE_SIMD_WIDE
#endif

