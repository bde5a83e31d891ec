#pragma once
// Private to libcore: the one place that decides which dispatched kernel runs (kernels.hpp).

namespace impinge::detail {

/// The rasteriser's AVX-512 (F, VL, DQ) span pass and row kernel: the CPU has them and the kernel
/// set is native.
bool use_avx512();

/// The equiangular grid's AVX2+FMA look-ups: the CPU has them and the kernel set is native.
bool use_avx2_fma();

}  // namespace impinge::detail
