#pragma once
/// @file timing.hpp
/// Wall-clock timing for the `*_ms` figures that results and summaries report.

#include <chrono>

namespace impinge {

/// Milliseconds of wall time (steady clock) since `t0`, e.g. `const auto t0 = Clock::now(); ...;
/// report.sampling_ms = ms_since(t0);`. Never throws.
using Clock = std::chrono::steady_clock;
inline double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

}  // namespace impinge
