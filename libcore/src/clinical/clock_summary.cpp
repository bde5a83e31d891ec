#include "impinge/clinical/clock_summary.hpp"

#include <cmath>
#include <limits>

#include "impinge/core/error.hpp"

namespace impinge {

void clock_summary(const ScanGaps& gaps, PointsRef V, const Eigen::VectorXd& area, const ClockFace& clock,
                   const ImpingementLevels& levels, ClockSummary& out) {
  out.sector_level_area_mm2.assign(static_cast<std::size_t>(12 * levels.count()), 0.0);
  out.closest_hour = std::nan("");
  float best = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < gaps.gap_mm.size(); ++i) {
    const float g = gaps.gap_mm[i];
    if (std::isnan(g)) continue;
    const Eigen::Vector3d p = V.row(static_cast<Eigen::Index>(i)).transpose();
    const double h = clock.hour(p);
    if (std::isnan(h)) continue;
    if (g < best) best = g, out.closest_hour = h;
    out.sector_level_area_mm2[static_cast<std::size_t>(ClockFace::sector(h) * levels.count() + levels.level(g))] +=
        area[static_cast<Eigen::Index>(i)];
  }
}

}  // namespace impinge
