#include "impinge/clinical/clock_summary.hpp"

#include <cmath>
#include <limits>

#include "impinge/core/error.hpp"

namespace impinge {

std::vector<double> clock_hours(PointsRef V, const ClockFace& clock) {
  std::vector<double> h(static_cast<std::size_t>(V.rows()));
  for (Eigen::Index i = 0; i < V.rows(); ++i) h[static_cast<std::size_t>(i)] = clock.hour(V.row(i).transpose());
  return h;
}

void clock_summary(const ScanGaps& gaps, PointsRef V, const Eigen::VectorXd& area, const ClockFace& clock,
                   const ImpingementLevels& levels, ClockSummary& out, LevelQuantity levels_on) {
  clock_summary(gaps, clock_hours(V, clock), area, levels, out, levels_on);
}

void clock_summary(const ScanGaps& gaps, const std::vector<double>& hours, const Eigen::VectorXd& area,
                   const ImpingementLevels& levels, ClockSummary& out, LevelQuantity levels_on) {
  require(hours.size() == gaps.gap_mm.size(), "clock summary: " + std::to_string(hours.size()) + " hours for " +
                                                  std::to_string(gaps.gap_mm.size()) + " vertices");
  require(gaps.status.size() == gaps.gap_mm.size() &&
              (gaps.distance_mm.empty() || gaps.distance_mm.size() == gaps.gap_mm.size()),
          "clock summary: " + std::to_string(gaps.gap_mm.size()) + " gaps with " + std::to_string(gaps.status.size()) +
              " statuses and " + std::to_string(gaps.distance_mm.size()) + " distances");
  const bool by_distance = levels_on == LevelQuantity::distance && !gaps.distance_mm.empty();
  out.sector_level_area_mm2.assign(static_cast<std::size_t>(12 * levels.count()), 0.0);
  out.closest_hour = std::nan("");
  float best = std::numeric_limits<float>::infinity();
  const std::size_t n = gaps.gap_mm.size();
  for (std::size_t i = 0; i < n; ++i) {
    int no_surface = 0;
    if (i % 8 == 0 && i + 8 <= n && eight_without_value(gaps, i, no_surface)) {  // most vertices: no level
      i += 7;
      continue;
    }
    if (vertex_unmeasured(gaps, i)) continue;
    const double h = hours[i];
    if (std::isnan(h)) continue;
    const std::uint8_t level = vertex_level(gaps, i, levels, levels_on);
    if (level == 255) continue;
    const float g = by_distance ? gaps.distance_mm[i] : gaps.gap_mm[i];
    if (g < best) best = g, out.closest_hour = h;  // NaN (a distance beyond the reach) never wins
    out.sector_level_area_mm2[static_cast<std::size_t>(ClockFace::sector(h) * levels.count() + level)] +=
        area[static_cast<Eigen::Index>(i)];
  }
}

}  // namespace impinge
