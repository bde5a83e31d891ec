#pragma once
/// @file map_image.hpp
/// A radial distance map as a grey-scale PNG (thesis Fig. 31: theta across, phi down).

#include <string>

#include "impinge/maps/radial_distance_map.hpp"

namespace impinge {

/// The grey scale of a map image: grey 40 is `nearest_mm`, 255 is `farthest_mm`, linear between;
/// 0 (black) is no surface. A figure's colour bar is drawn from it.
struct MapImageScale {
  double nearest_mm = 0;   ///< smallest covered distance in the image, mm
  double farthest_mm = 0;  ///< largest covered distance in the image, mm
};

/// Write `map` as an 8-bit grey PNG: theta across (0 at the left), phi down (0 at the top); for
/// an equiangular map one pixel per node (columns x rows), for another scheme the map
/// interpolated on an equiangular pixel grid matched to its node spacing (at most 0.1 deg). Covered nodes are grey from
/// 40 (nearest) to 255 (farthest, normalised over the map); nodes with no surface are black (0). Throws impinge::Error
/// if the file cannot be written. Returns the grey scale, for a colour bar.
MapImageScale write_map_png(const std::string& path, const RadialDistanceMap& map);

}  // namespace impinge
