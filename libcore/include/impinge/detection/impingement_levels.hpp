#pragma once
/// @file impingement_levels.hpp
/// Gap classes after a cartilage offset (thesis sec. 3.4 and 5.2, Fig. 41).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace impinge {

/// Impingement-level thresholds. Level 0 ("none") when gap >= thresholds_mm[0] (the cartilage
/// offset, 4 mm in the thesis); level k (1 = yellow, 2 = orange, 3 = red) when
/// thresholds_mm[k] <= gap < thresholds_mm[k-1]; the last level (purple) when gap <= the last
/// threshold (0 mm: the bones touch or penetrate). Thresholds strictly decreasing.
/// Defaults split the 4 mm offset into equal thirds (the thesis names the colours, not the
/// bounds).
struct ImpingementLevels {
  std::vector<double> thresholds_mm{4.0, 8.0 / 3.0, 4.0 / 3.0, 0.0};  ///< mm, decreasing
  /// Number of levels: thresholds + 1.
  int count() const { return static_cast<int>(thresholds_mm.size()) + 1; }
  /// Level of a finite gap in mm.
  std::uint8_t level(double gap_mm) const;
  /// Throws impinge::Error unless at least one threshold, all finite and strictly decreasing.
  void validate() const;
  /// Names: none, yellow, orange, red, purple (generic "level_k" beyond five levels).
  std::string name(int level) const;
};

/// Colour (RGB) of a level for the ball (none = green) or socket (none = blue), thesis
/// sec. 3.4; level 255 (untested) is light grey.
std::array<std::uint8_t, 3> level_colour(std::uint8_t level, int level_count, bool is_ball);

/// Parse "4,2.667,1.333,0" into thresholds; throws impinge::Error on a bad list.
ImpingementLevels parse_levels(const std::string& csv);

}  // namespace impinge
