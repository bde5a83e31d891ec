#include "impinge/clinical/clock_summary.hpp"

#include <cmath>
#include <limits>

#include "impinge/core/error.hpp"

namespace impinge {

void clock_summary(const ScanGaps& gaps, PointsRef V, const Eigen::VectorXd& area, const ClockFace& clock,
                   const ImpingementLevels& levels, ClockSummary& out, LevelQuantity levels_on) {
  const bool by_distance = levels_on == LevelQuantity::distance && !gaps.distance_mm.empty();
  out.sector_level_area_mm2.assign(static_cast<std::size_t>(12 * levels.count()), 0.0);
  out.closest_hour = std::nan("");
  float best = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < gaps.gap_mm.size(); ++i) {
    const std::uint8_t level = vertex_level(gaps, i, levels, levels_on);
    if (level == 255) continue;
    const float g = by_distance ? gaps.distance_mm[i] : gaps.gap_mm[i];
    const Eigen::Vector3d p = V.row(static_cast<Eigen::Index>(i)).transpose();
    const double h = clock.hour(p);
    if (std::isnan(h)) continue;
    if (g < best) best = g, out.closest_hour = h;  // NaN (a distance beyond the reach) never wins
    out.sector_level_area_mm2[static_cast<std::size_t>(ClockFace::sector(h) * levels.count() + level)] +=
        area[static_cast<Eigen::Index>(i)];
  }
}

}  // namespace impinge
