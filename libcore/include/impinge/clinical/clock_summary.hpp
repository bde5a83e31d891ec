#pragma once
/// @file clock_summary.hpp
/// Where a scan's contacts lie on a clock face (anatomy/clock_face.hpp): the hour of the closest
/// vertex and the contact area per hour sector and impingement level (thesis sec. 5.2, Tables 11-13).

#include <Eigen/Core>
#include <vector>

#include "impinge/anatomy/clock_face.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/detection/detection.hpp"
#include "impinge/detection/impingement_levels.hpp"

namespace impinge {

/// Where a scan's contact lies on a clock face.
struct ClockSummary {
  double closest_hour = 0;                    ///< clock position of the tested vertex with the least gap, hours; NaN if none
  std::vector<double> sector_level_area_mm2;  ///< 12 x levels: vertex area (mm^2) of the tested vertices in hour
                                              ///< sector k (hours (k, k+1]) at level l, at [k * levels + l]
};

/// Clock summary of one scan: `gaps` (n vertices), their positions V (n x 3, mm, the frame of
/// `clock`, unposed: the clock moves with its bone), vertex areas (n, mm^2). Into `out`. Levels and the
/// closest hour by `levels_on` (vertex_level; the radial gap, or the Euclidean distance).
void clock_summary(const ScanGaps& gaps, PointsRef V, const Eigen::VectorXd& area, const ClockFace& clock,
                   const ImpingementLevels& levels, ClockSummary& out,
                   LevelQuantity levels_on = LevelQuantity::radial_gap);

/// Every vertex's clock hour (ClockFace::hour of V's rows: n x 3, mm, the clock's frame; NaN where the
/// clock gives none). A bone's hours do not change with its pose: compute them once, then summarise
/// each pose with the overload below.
std::vector<double> clock_hours(PointsRef V, const ClockFace& clock);

/// clock_summary with the vertices' hours given (clock_hours: n values), for many poses of one bone.
/// Throws impinge::Error when `hours` does not have one value per vertex of `gaps`, or `gaps` has not one
/// status (and, when it has distances, one distance) per gap.
void clock_summary(const ScanGaps& gaps, const std::vector<double>& hours, const Eigen::VectorXd& area,
                   const ImpingementLevels& levels, ClockSummary& out,
                   LevelQuantity levels_on = LevelQuantity::radial_gap);

}  // namespace impinge
