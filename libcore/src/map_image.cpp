#include "impinge/map_image.hpp"

#include <png.h>

#include <cstdio>
#include <limits>
#include <vector>

#include "impinge/error.hpp"

namespace impinge {

namespace {
/// libpng's error handling longjmps: keep this frame free of locals computed before setjmp.
void write_grey_png(const std::string& path, const unsigned char* pixels, int w, int h) {
  FILE* fp = std::fopen(path.c_str(), "wb");
  require(fp != nullptr, path + ": cannot open for writing");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(fp);
    throw Error(path + ": PNG write failed");
  }
  png_init_io(png, fp);
  png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), 8, PNG_COLOR_TYPE_GRAY,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int r = 0; r < h; ++r) png_write_row(png, const_cast<unsigned char*>(pixels + std::int64_t(r) * w));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  require(std::fclose(fp) == 0, path + ": PNG write failed");
}
}  // namespace


void write_map_png(const std::string& path, const RadialDistanceMap& map) {
  const int w = map.grid().columns(), h = map.grid().rows();
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (std::int64_t i = 0; i < map.num_nodes(); ++i)
    if (map.has_surface(i)) lo = std::min<double>(lo, map.at(i)), hi = std::max<double>(hi, map.at(i));
  const double span = hi > lo ? hi - lo : 1.0;
  std::vector<unsigned char> pixels(static_cast<std::size_t>(map.num_nodes()));
  for (std::int64_t i = 0; i < map.num_nodes(); ++i)
    pixels[static_cast<std::size_t>(i)] =
        map.has_surface(i) ? static_cast<unsigned char>(40 + 215.0 * (map.at(i) - lo) / span) : 0;
  write_grey_png(path, pixels.data(), w, h);
}

}  // namespace impinge
