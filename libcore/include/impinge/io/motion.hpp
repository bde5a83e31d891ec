#pragma once
/// @file motion.hpp
/// A hip motion: a sequence of clinical poses with times, read from a CSV file or an OpenSim
/// motion / storage file (.mot, .sto; OpenSim's gait2392 and Rajagopal hip coordinates
/// hip_flexion, hip_adduction, hip_rotation use the ISB signs of PoseAngles).

#include <string>
#include <vector>

#include "impinge/anatomy/pose.hpp"

namespace impinge {

/// A motion: frame k is at time_s[k] with angles[k] (degrees, ISB signs).
struct Motion {
  std::vector<double> time_s;      ///< k times, s
  std::vector<PoseAngles> angles;  ///< k poses, degrees
  std::string source;              ///< file name
  std::string format;              ///< "csv" or "opensim"
  std::size_t frames() const { return angles.size(); }
};

/// Read a motion file for the hip of `side`.
/// - CSV (any other extension): a header row naming the columns `time_s`, `flexion_deg`,
///   `adduction_deg`, `internal_rotation_deg` (in any order; other columns ignored), then one
///   row per frame, comma-separated.
/// - OpenSim (.mot, .sto): header lines up to `endheader` that must say `inDegrees=yes` or
///   `inDegrees=no`; then a tab- or space-separated row of column labels with `time` and
///   `hip_flexion_r`, `hip_adduction_r`, `hip_rotation_r` (`_l` for the left side; OpenSim 4
///   path labels such as `/jointset/hip_r/hip_flexion_r/value` also match); then one row per frame.
///   Radians are converted to degrees.
/// Throws impinge::Error with one line naming the file, line and column on: an unreadable or
/// empty file, a missing column, a missing or unknown inDegrees, a row with too few cells, a
/// non-numeric or non-finite cell, times that decrease, or no frames.
Motion load_motion(const std::string& path, Side side);

}  // namespace impinge
