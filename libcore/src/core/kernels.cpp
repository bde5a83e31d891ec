#include "impinge/core/kernels.hpp"

#include <atomic>
#include <cstdlib>
#include <string>

#include "core/cpu_dispatch.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

namespace {

KernelSet from_environment() {
  const char* v = std::getenv("IMPINGE_KERNELS");
  const std::string s = v == nullptr ? "" : v;
  if (s.empty() || s == "native") return KernelSet::native;
  if (s == "generic") return KernelSet::generic;
  throw Error("IMPINGE_KERNELS='" + s + "': expected 'native' or 'generic'");
}

// -1: not read yet; otherwise a KernelSet.
std::atomic<int> g_set{-1};

bool native() {
  int s = g_set.load(std::memory_order_relaxed);
  if (s < 0) {
    s = static_cast<int>(from_environment());
    g_set.store(s, std::memory_order_relaxed);
  }
  return s == static_cast<int>(KernelSet::native);
}

#if defined(__GNUC__) && defined(__x86_64__)
bool cpu_avx512() {
  static const bool yes =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq");
  return yes;
}
bool cpu_avx2_fma() {
  static const bool yes = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return yes;
}
bool cpu_x86_64_v4() {
#ifdef IMPINGE_SIMD_NO_AVX512
  return false;
#else
  static const bool yes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                          __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
                          __builtin_cpu_supports("avx512cd");
  return yes;
#endif
}
#else
bool cpu_avx512() { return false; }
bool cpu_avx2_fma() { return false; }
bool cpu_x86_64_v4() { return false; }
#endif

}  // namespace

KernelSet kernel_set() { return native() ? KernelSet::native : KernelSet::generic; }

void set_kernel_set(KernelSet set) { g_set.store(static_cast<int>(set), std::memory_order_relaxed); }

std::string kernel_description() {
  return std::string("rasteriser ") + (detail::use_avx512() ? "avx512" : "generic") + ", look-ups " +
         (detail::use_avx2_fma() ? "avx2" : "generic") + ", fibonacci stencils " +
         (detail::use_avx512() ? "avx512" : "generic") + ", distance bounds and joint-centre sums " +
         (detail::use_wide_vectors() ? "avx512" : "generic");
}

namespace detail {
bool use_avx512() { return cpu_avx512() && native(); }
bool use_avx2_fma() { return cpu_avx2_fma() && native(); }
bool use_wide_vectors() { return cpu_x86_64_v4() && native(); }
}  // namespace detail

}  // namespace impinge
