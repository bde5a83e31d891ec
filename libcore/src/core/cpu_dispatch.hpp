#pragma once
// Private to libcore: the one place that decides which dispatched kernel runs (kernels.hpp).

namespace impinge::detail {

/// The rasteriser's AVX-512 (F, VL, DQ) span pass and row kernel: the CPU has them and the kernel
/// set is native.
bool use_avx512();

/// The equiangular grid's AVX2+FMA look-ups: the CPU has them and the kernel set is native.
bool use_avx2_fma();

/// The AVX-512 forms of the kernels written twice over GCC vectors (core/simd_clones.hpp: IMPINGE_SIMD_WIDE against
/// IMPINGE_SIMD_CLONES_NARROW; the distance scans' lower bounds, the joint centre's normal sums): the CPU has
/// x86-64-v4's AVX-512 (F, VL, BW, DQ, CD), the kernel set is native, and the build does not leave them out
/// (-DIMPINGE_SIMD_NO_AVX512).
bool use_wide_vectors();

}  // namespace impinge::detail
