#pragma once
/// @file kernels.hpp
/// Which implementation the CPU-dispatched hot loops run: the rasteriser's span pass and exact row
/// kernel (AVX-512 F/VL/DQ or generic C++), the equiangular grid's bilinear look-ups (AVX2+FMA or
/// generic C++), the Fibonacci lattice's block stencils (AVX-512 F/VL/DQ or generic), and the distance
/// scans' lower bounds and the joint centre's normal sums (16 lanes in one AVX-512 register, or 8 and 4
/// lanes at a time, compiled for AVX2 and the baseline). Both halves of every pair compute the same formulas;
/// the generic one runs on any x86-64 (and any other) CPU. Forcing `generic` on an AVX-512 machine tests the
/// half that other machines run, and A/B-measures the vector kernels.
/// Not covered: the rest of the functions that GCC compiles per ISA level from one source (`target_clones`);
/// they are chosen by the loader.

#include <string>

namespace impinge {

/// The kernel families.
enum class KernelSet {
  native,   ///< the fastest this CPU supports (the default)
  generic,  ///< the portable C++ kernels, whatever the CPU
};

/// The kernels in use. Starts as `generic` when the environment variable IMPINGE_KERNELS is
/// "generic", `native` when it is unset, empty or "native".
/// Throws impinge::Error naming IMPINGE_KERNELS and its value for any other value.
KernelSet kernel_set();

/// Choose the kernels for every later call, in every thread. Call it while no detection or
/// rasterisation runs (it is not synchronised with running kernels). Results do not depend on it
/// beyond rounding (tested: the same maps node for node, the same gaps).
void set_kernel_set(KernelSet set);

/// What runs now, for meta data and logs: e.g. "rasteriser avx512, look-ups avx2, fibonacci
/// stencils avx512, distance bounds and joint-centre sums avx512" or the same with "generic" throughout.
std::string kernel_description();

}  // namespace impinge
