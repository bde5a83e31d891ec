// The map PNG has columns x rows pixels (theta across, phi down): checked in the IHDR chunk; the
// returned grey scale spans the covered values.
#include "impinge/maps/map_image.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "impinge/core/error.hpp"
#include "impinge/schemes/equiangular_grid.hpp"
#include "test_support.hpp"

using namespace impinge;

TEST(MapImage, DimensionsAndErrors) {
  RadialDistanceMap map{EquiangularGrid(2)};
  for (std::int64_t i = 0; i < map.num_nodes() / 3; ++i) map.data()[i] = 10 + i % 7;
  const std::string d = test::temp_dir("map_image");
  const MapImageScale sc = write_map_png(d + "/m.png", map);
  EXPECT_EQ(sc.nearest_mm, 10);  // the covered values are 10 .. 16 mm
  EXPECT_EQ(sc.farthest_mm, 16);
  std::ifstream in(d + "/m.png", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 33u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  auto be32 = [&](std::size_t o) {
    return (std::uint32_t(std::uint8_t(bytes[o])) << 24) | (std::uint32_t(std::uint8_t(bytes[o + 1])) << 16) |
           (std::uint32_t(std::uint8_t(bytes[o + 2])) << 8) | std::uint32_t(std::uint8_t(bytes[o + 3]));
  };
  EXPECT_EQ(be32(16), 180u);  // width: 360 / 2 columns
  EXPECT_EQ(be32(20), 91u);   // height: 180 / 2 + 1 rows
  EXPECT_THROW(write_map_png("/nonexistent-dir/m.png", map), Error);
}
