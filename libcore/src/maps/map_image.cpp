#include "impinge/maps/map_image.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "impinge/core/atomic_file.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/schemes/equiangular_grid.hpp"

namespace impinge {

namespace {
/// libpng's error handling longjmps: keep this frame free of locals computed before setjmp.
void write_grey_png(const std::string& file, const std::string& path, const unsigned char* pixels, int w, int h) {
  FILE* fp = std::fopen(file.c_str(), "wb");
  require(fp != nullptr, path + ": cannot open for writing");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(fp);
    throw Error(path + ": PNG write failed");
  }
  png_init_io(png, fp);
  // zlib's fastest level: a map image is written on every run and read rarely; the pixels are the same, the file
  // some 50 % larger (20 against 14 KB at 0.5 deg) than at zlib's default level, and written several times faster.
  png_set_compression_level(png, 1);
  png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), 8, PNG_COLOR_TYPE_GRAY,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int r = 0; r < h; ++r) png_write_row(png, const_cast<unsigned char*>(pixels + std::int64_t(r) * w));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  require(std::fclose(fp) == 0, path + ": PNG write failed");
}
}  // namespace

MapImageScale write_map_png(const std::string& path, const RadialDistanceMap& map) {
  // Pixel values: the node values of a map conformable with an equiangular grid, else the map interpolated at the
  // nodes of an equiangular image grid matched to the scheme's spacing (at most 3600 x 1801).
  std::vector<double> value;
  int w, h;
  if (const auto g = conformable_equiangular_grid(map.scheme())) {
    w = g->columns(), h = g->rows();
    value.resize(static_cast<std::size_t>(map.num_nodes()));
    for (std::int64_t i = 0; i < map.num_nodes(); ++i) value[static_cast<std::size_t>(i)] = map.at(i);  // dense or sparse
  } else {
    const EquiangularGrid img(
        matched_equiangular_precision(std::max(map.scheme().max_node_spacing(), 0.1 * kDegToRad)));
    w = img.columns(), h = img.rows();
    value.resize(static_cast<std::size_t>(img.num_nodes()));
    for (std::int64_t i = 0; i < img.num_nodes(); ++i) {
      const double v = map.lookup(img.node_direction(i));
      value[static_cast<std::size_t>(i)] = std::isnan(v) ? std::numeric_limits<double>::infinity() : v;
    }
  }
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (double v : value)
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  const double span = hi > lo ? hi - lo : 1.0;
  std::vector<unsigned char> pixels(value.size());
  for (std::size_t i = 0; i < value.size(); ++i)
    pixels[i] = std::isfinite(value[i]) ? static_cast<unsigned char>(40 + 215.0 * (value[i] - lo) / span) : 0;
  AtomicFile file(path);  // written whole or not at all
  write_grey_png(file.temp_path(), path, pixels.data(), w, h);
  file.commit();
  return {std::isfinite(lo) ? lo : 0.0, hi};
}

}  // namespace impinge
